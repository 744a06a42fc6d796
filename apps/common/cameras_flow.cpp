// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// rawgment_cameras: the catalogue of a darktable noise-profile file, one camera's fit per ISO, and the
// report of what the measured cameras say about the model of Eq. 5.
#include "pipeline.hpp"

#include "app_tools.hpp"
#include "plots.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

namespace rawgment_apps {

using namespace cv::rawgment;

namespace {

double quantile(std::vector<double> v, double q)
{
    if (v.empty())
        return std::nan("");
    std::sort(v.begin(), v.end());
    const double at = q * double(v.size() - 1);
    const size_t lo = size_t(std::floor(at)), hi = std::min(lo + 1, v.size() - 1);
    return v[lo] + (at - double(lo)) * (v[hi] - v[lo]);
}

//! Share of the read variance that comes before the gain, at the camera's base or highest ISO.
double preGainShare(const CameraNoiseProfile& cam, bool highest = true)
{
    const double g = highest ? cam.isos.back().gain : 1.0;
    // The line's offset less the part after the gain.
    const double total = cam.noise.lineAtGain(g).b, before = total - cam.noise.sigmaR2;
    return total > 0 ? before / total : std::nan("");
}

//! Read noise at the base ISO in electrons: sqrt(sigma_d^2 + sigma_r^2) / alpha.
double readElectrons(const CameraNoiseProfile& cam)
{
    return std::sqrt(cam.noise.lineAtGain(1).b) / cam.noise.alpha;
}

//! The measured lines the camera's model carries, which the augmentation follows: one per consistent ISO.
int measuredLineCount(const CameraNoiseProfile& cam)
{
    std::set<double> isos;
    for (const CameraIsoFit& f : cam.isos)
        if (!f.inconsistent)
            isos.insert(f.iso);
    return int(isos.size());
}

std::string catalogueLine(const CameraNoiseProfile& cam)
{
    if (!cam.usable())
        return cv::format("%-34s %-8s %s", cam.name().c_str(), "REFUSED", cam.reason.c_str());
    return cv::format(
        "%-34s %-8s %4zu %5d %6g %9.0f %7.2f %6.2f %6.1f%% %6.1f%% %6.1f%% %5.2f  %-9s %6.4f  %s",
        cam.name().c_str(), cameraProfileVerdictName(cam.verdict).c_str(), cam.isos.size(),
        measuredLineCount(cam), cam.noise.baseIso, 1 / cam.noise.alpha, readElectrons(cam), preGainShare(cam),
        100 * cam.medianSlopeResidual, 100 * cam.worstSlopeResidual, 100 * cam.worstOffsetResidual,
        cam.medianColourSpread, profileDemosaicName(cam.demosaic).c_str(), cam.haarVarianceRatio,
        cam.reason.c_str());
}

const char* kCatalogueHeader =
    "camera                             verdict  ISOs lines   base  full-well   read  pre-g  "
    "slope~  slope^  offs^ colour  demosaic       c  reason\n"
    "                                                   (Eq. 5:)   (e-)   (e-)  share  "
    " med    worst  worst  spread\n";

std::string isoTable(const CameraNoiseProfile& cam)
{
    std::ostringstream out;
    out << cam.name() << " (" << cam.place << "): " << cameraProfileVerdictName(cam.verdict)
        << (cam.reason.empty() ? "" : " - " + cam.reason) << "\n";
    if (!cam.usable())
        return out.str();
    out << cv::format(
        "fit over a range of 1: alpha %.4g (full well %.0f e-), sigma_d^2 %.4g, sigma_r^2 %.4g, base "
        "ISO %g\n",
        cam.noise.alpha, 1 / cam.noise.alpha, cam.noise.sigmaD2, cam.noise.sigmaR2, cam.noise.baseIso);
    out << cv::format("demosaic of the profiles: %s (%s); c = %.4f\n",
                      profileDemosaicName(cam.demosaic).c_str(), cam.demosaicReason.c_str(),
                      cam.haarVarianceRatio);
    out << "     ISO    gain   slope (a/c)  Eq. 5        resid   offset (b/c)  Eq. 5        resid  colours  "
           "R/G   B/G   setting\n";
    for (const CameraIsoFit& f : cam.isos) {
        const NoiseLine fitted = cam.noise.lineAtGain(f.gain);
        const std::string setting = f.inconsistent ? "inconsistent colours (not used)"
                                    : f.expanded   ? "expanded (not fitted)"
                                    : f.digital()
                                        ? cv::format("digital, the raw of ISO %g (not fitted)", f.rawIso)
                                        : "fitted";
        out << cv::format(
            "%8g %7.3f  %11.4g  %11.4g %6.1f%%  %11.4g  %11.4g %6.1f%%  %5.2f  %5.2f %5.2f  %s\n", f.iso,
            f.gain, f.slope, fitted.a, 100 * f.slopeResidual, f.offset, fitted.b, 100 * f.offsetResidual,
            f.colourSpread, f.colourSlopeRatios[0], f.colourSlopeRatios[1], setting.c_str());
    }
    out << "The augmentation follows the measured slope and offset at each ISO that is not inconsistent; the "
           "Eq. 5 columns are the fit's summary.\n";
    return out.str();
}

/* Each usable profile's shot slope in the camera's model (its measured lines) and in Eq. 5's fit alone, as
 * |used / (a / c) - 1|: the model is taken in DN of a 16-bit range and scaled back. */
void addSlopeErrors(const CameraNoiseProfile& cam, std::vector<double>& lines, std::vector<double>& eq5)
{
    RawFormat format;
    format.whiteLevel = 65535;
    const double r = format.whiteLevel - format.blackLevel[0];
    const NoiseModel model = cam.modelFor(format);
    NoiseModel summary = model;
    summary.measuredLines.clear();
    for (const CameraIsoFit& f : cam.isos) {
        const double g = f.iso / model.baseIso;
        lines.push_back(std::abs(model.lineAtGain(g).a / r / f.slope - 1));
        eq5.push_back(std::abs(summary.lineAtGain(g).a / r / f.slope - 1));
    }
}

std::string formatShare(int part, int whole)
{
    return cv::format("%d of %d (%.0f%%)", part, whole, whole ? 100.0 * part / whole : 0.0);
}

//! The report's tables and conclusions, from the fitted cameras.
std::string reportText(const std::vector<CameraNoiseProfile>& cams, const std::string& path, double seconds,
                       const std::vector<std::string>& pngs)
{
    std::map<int, int> verdicts;
    std::map<std::string, int> refusals;
    std::vector<double> medianSlope, worstSlope, worstOffset, medianOffset, fullWell, read, share, baseShare,
        spread;
    int negative = 0, nonMonotone = 0, usable = 0, lowestWorst = 0, expanded = 0, inconsistent = 0,
        digital = 0;
    std::map<int, int> demosaics;
    std::vector<double> balancePpg, balanceRcd, linesError, eq5Error;
    for (const CameraNoiseProfile& cam : cams) {
        ++verdicts[cam.verdict];
        if (!cam.usable()) {
            // The kind of refusal: the reason up to its colon, with each count ("at all 12 ISOs") as N.
            const std::string reason = cam.reason.substr(0, cam.reason.find(':'));
            std::string kind;
            for (size_t k = 0; k < reason.size(); ++k) {
                const bool digit = reason[k] >= '0' && reason[k] <= '9';
                if (digit && k > 0 && reason[k - 1] == ' ')
                    kind += 'N';
                else if (!digit || kind.empty() || kind.back() != 'N')
                    kind += reason[k];
            }
            ++refusals[kind];
            continue;
        }
        ++usable;
        medianSlope.push_back(cam.medianSlopeResidual);
        worstSlope.push_back(cam.worstSlopeResidual);
        worstOffset.push_back(cam.worstOffsetResidual);
        std::vector<double> offsets;
        double lowestFitted = 0;
        for (const CameraIsoFit& f : cam.isos)
            if (f.fitted()) {
                offsets.push_back(std::abs(f.offsetResidual));
                lowestFitted = lowestFitted > 0 ? lowestFitted : f.iso;
            }
        medianOffset.push_back(quantile(offsets, 0.5));
        fullWell.push_back(1 / cam.noise.alpha);
        read.push_back(readElectrons(cam));
        share.push_back(preGainShare(cam));
        baseShare.push_back(preGainShare(cam, false));
        spread.push_back(cam.medianColourSpread);
        negative += cam.negativeOffsets > 0;
        nonMonotone += !cam.monotoneSlope;
        lowestWorst += cam.worstSlopeIso == lowestFitted;
        expanded += cam.expandedIsos > 0;
        inconsistent += cam.inconsistentProfiles > 0;
        digital += cam.digitalIsos > 0;
        ++demosaics[cam.demosaic];
        if (cam.demosaic == PROFILE_DEMOSAIC_UNDECIDED && cam.balancePpg[0] > 0) {
            balancePpg.push_back(cam.balancePpg[0]);
            balancePpg.push_back(cam.balancePpg[1]);
            balanceRcd.push_back(cam.balanceRcd[0]);
            balanceRcd.push_back(cam.balanceRcd[1]);
        }
        addSlopeErrors(cam, linesError, eq5Error);
    }
    const auto row = [](const char* what, const std::vector<double>& v, double scale, const char* unit) {
        return cv::format("| %s | %.3g%s | %.3g%s | %.3g%s | %.3g%s | %.3g%s |\n", what,
                          scale * quantile(v, 0.1), unit, scale * quantile(v, 0.25), unit,
                          scale * quantile(v, 0.5), unit, scale * quantile(v, 0.75), unit,
                          scale * quantile(v, 0.9), unit);
    };
    std::ostringstream md;
    md << "## The cameras\n\n"
       << cv::format("`%s`: %zu cameras, read and fitted in %.2f s. ",
                     path.substr(path.find_last_of('/') + 1).c_str(), cams.size(), seconds)
       << "Verdicts: " << verdicts[CAMERA_PROFILE_GOOD] << " GOOD, " << verdicts[CAMERA_PROFILE_ROUGH]
       << " ROUGH, " << verdicts[CAMERA_PROFILE_REFUSED] << " REFUSED.\n\n";
    if (!refusals.empty()) {
        md << "| refused because | cameras |\n|---|---|\n";
        for (const auto& r : refusals)
            md << "| " << r.first << " | " << r.second << " |\n";
        md << "\n";
    }
    md << "## How well Eq. 5 describes them\n\n"
       << "Over the " << usable
       << " imported cameras (GOOD and ROUGH), the distribution across cameras of each measure:\n\n"
       << "| measure | 10% | 25% | median | 75% | 90% |\n|---|---|---|---|---|---|\n"
       << row("median over ISOs of the shot-slope residual", medianSlope, 100, "%")
       << row("worst shot-slope residual", worstSlope, 100, "%")
       << row("median over ISOs of the offset residual", medianOffset, 100, "%")
       << row("worst offset residual", worstOffset, 100, "%")
       << row("colours' slope spread (largest / smallest)", spread, 1, "") << "\n"
       << "- Cameras with expanded low ISOs (a slope that falls less than the ISO below the next ISO: left "
          "out of the fit and of these figures, never the base ISO, followed by the augmentation as "
          "measured): "
       << formatShare(expanded, usable) << ".\n"
       << "- Cameras with digital settings (neighbouring ISOs a third of a stop or more apart with one "
          "slope: "
          "one raw, such as Canon's third stops 160, 320, 640; left out of the fit and of these figures, "
          "followed as measured): "
       << formatShare(digital, usable) << ".\n"
       << "- Cameras with a profile whose red or blue shot slope is negative (a failed fit: left out of "
          "the fit, these figures and the measured lines): "
       << formatShare(inconsistent, usable) << ".\n"
       << "- The shot slope's worst fitted ISO is the camera's lowest for "
       << formatShare(lowestWorst, usable) << " of the cameras.\n"
       << "- Cameras with a negative offset at some ISO: " << formatShare(negative, usable) << ".\n"
       << "- Cameras whose measured slope falls somewhere as the ISO rises: "
       << formatShare(nonMonotone, usable) << ".\n\n"
       << "## What the augmentation follows\n\n"
       << "At every measured ISO of the " << usable << " imported cameras (" << linesError.size()
       << " profiles), the shot slope of the camera's model against darktable's a / c:\n\n"
       << "| slope used | median | 90th percentile |\n|---|---:|---:|\n"
       << cv::format("| the measured lines (what the augmentation follows) | %.1f%% | %.1f%% |\n",
                     100 * quantile(linesError, 0.5), 100 * quantile(linesError, 0.9))
       << cv::format("| Eq. 5's fit alone (the summary above) | %.1f%% | %.1f%% |\n\n",
                     100 * quantile(eq5Error, 0.5), 100 * quantile(eq5Error, 0.9))
       << "## Which demosaic the profiles were made with\n\n"
       << "| demosaic | cameras |\n|---|---|\n";
    for (const auto& d : demosaics)
        md << "| " << profileDemosaicName(d.first) << " | " << d.second << " |\n";
    md << "\nWhere both fit, the colour balance (green over red and blue raw level of the profiling shot) "
          "each "
          "implies, over the colours of those cameras: PPG "
       << cv::format("%.2f (median; 10%%-90%%: %.2f-%.2f), RCD %.2f (%.2f-%.2f).\n\n",
                     quantile(balancePpg, 0.5), quantile(balancePpg, 0.1), quantile(balancePpg, 0.9),
                     quantile(balanceRcd, 0.5), quantile(balanceRcd, 0.1), quantile(balanceRcd, 0.9))
       << "## The fitted parameters\n\n"
       << "| parameter | 10% | 25% | median | 75% | 90% |\n|---|---|---|---|---|---|\n"
       << row("full well at base ISO, 1 / alpha (e-)", fullWell, 1, "")
       << row("read noise at base ISO (e-)", read, 1, "")
       << row("share of read variance before the gain, at the base ISO", baseShare, 1, "")
       << row("share of read variance before the gain, at the highest ISO", share, 1, "") << "\n";
    for (const std::string& png : pngs) {
        const std::string name = png.substr(png.find_last_of('/') + 1);
        md << "![" << name << "](" << name << ")\n\n";
    }
    return md.str();
}

//! The per-ISO points of every imported camera, and one line per camera, for the plots.
void writeReportTables(const std::string& dir, const std::vector<CameraNoiseProfile>& cams)
{
    CsvTable points({"iso", "slope_over_fit", "offset_residual"});
    CsvTable cameras({"camera",
                      "verdict",
                      "isos",
                      "base_iso",
                      "alpha",
                      "sigma_d2",
                      "sigma_r2",
                      "full_well_e",
                      "read_e",
                      "pre_gain_share",
                      "base_pre_gain_share",
                      "median_slope_residual",
                      "worst_slope_residual",
                      "worst_slope_iso",
                      "worst_offset_residual",
                      "worst_offset_iso",
                      "colour_spread",
                      "negative_offsets",
                      "monotone_slope",
                      "reason"});
    for (const CameraNoiseProfile& cam : cams) {
        if (cam.usable())
            for (const CameraIsoFit& f : cam.isos)
                points.addRow(
                    std::vector<double>{f.iso, f.slope / cam.noise.lineAtGain(f.gain).a, f.offsetResidual});
        std::string name = cam.name(), reason = cam.reason;
        for (std::string* s : {&name, &reason})
            std::replace(s->begin(), s->end(), ',', ';');
        cameras.addRow(std::vector<std::string>{name,
                                                cameraProfileVerdictName(cam.verdict),
                                                std::to_string(cam.isos.size()),
                                                formatNumber(cam.noise.baseIso),
                                                formatNumber(cam.noise.alpha),
                                                formatNumber(cam.noise.sigmaD2),
                                                formatNumber(cam.noise.sigmaR2),
                                                cam.usable() ? formatNumber(1 / cam.noise.alpha) : "",
                                                cam.usable() ? formatNumber(readElectrons(cam)) : "",
                                                cam.usable() ? formatNumber(preGainShare(cam)) : "",
                                                cam.usable() ? formatNumber(preGainShare(cam, false)) : "",
                                                formatNumber(cam.medianSlopeResidual),
                                                formatNumber(cam.worstSlopeResidual),
                                                formatNumber(cam.worstSlopeIso),
                                                formatNumber(cam.worstOffsetResidual),
                                                formatNumber(cam.worstOffsetIso),
                                                formatNumber(cam.medianColourSpread),
                                                std::to_string(cam.negativeOffsets),
                                                cam.monotoneSlope ? "1" : "0",
                                                reason});
    }
    points.write(dir + "/iso_points.csv");
    cameras.write(dir + "/cameras.csv");
}

PlotsWritten plotReport(const std::string& dir)
{
    PlotsWritten out;
    std::string message;
    const std::string slope = dir + "/real_cameras_slope.png";
    if (plotWithGnuplot(slope,
                        "set logscale x\nset key off\n"
                        "set title 'Measured shot slope over the fitted g alpha, every ISO of every imported "
                        "camera'\nset xlabel 'ISO'\nset ylabel 'slope / (g alpha)'\nset yrange [0:2.5]\n"
                        "set grid\nplot " +
                            gnuplotString(dir + "/iso_points.csv") +
                            " every ::1 using 1:2 with points pt 7 ps 0.4 lc rgb '#3060a0', 1 "
                            "with lines lw 2 lc rgb 'black'\n",
                        message))
        out.pngs.push_back(slope);
    else
        out.notes.push_back(message);
    const std::string params = dir + "/real_cameras_parameters.png";
    if (plotWithGnuplot(
            params,
            "set multiplot layout 1,2\nset key off\nset grid\n"
            "set logscale x\nset title 'Full well and read noise at base ISO (imported cameras)'\n"
            "set xlabel 'full well 1/alpha (e-)'\nset ylabel 'read noise (e-)'\nset logscale y\n"
            "plot " +
                gnuplotString(dir + "/cameras.csv") +
                " every ::1 using 8:9 with points pt 7 ps 0.6 lc rgb '#a03030'\n"
                "unset logscale\nset title 'Share of read variance before the gain, base ISO'\n"
                "set xlabel 'share'\nset ylabel 'cameras'\nset xrange [0:1]\nset boxwidth 0.05\n"
                "set style fill solid 0.6\nbin(x) = 0.05 * floor(x / 0.05) + 0.025\nplot " +
                gnuplotString(dir + "/cameras.csv") +
                " every ::1 using (bin($11)):(1) smooth frequency with boxes lc rgb "
                "'#30a060'\nunset multiplot\n",
            message, 1400, 600))
        out.pngs.push_back(params);
    else
        out.notes.push_back(message);
    return out;
}

} // namespace

CamerasResult runCameras(const CamerasOptions& o)
{
    const std::string path = o.profiles.empty() ? darktableProfilesPath() : o.profiles;
    if (path.empty())
        throw std::runtime_error(
            "no darktable noise-profile file: give --profiles=<noiseprofiles.json> (darktable "
            "installs it in /usr/share/darktable; scripts/fetch-darktable-profiles.sh fetches "
            "it without darktable)");
    CamerasResult r;
    const auto start = std::chrono::steady_clock::now();
    const std::vector<CameraNoiseProfile> cams = readCameraProfiles(path);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!o.camera.empty()) {
        for (const CameraNoiseProfile& cam : selectCameraProfiles(cams, o.camera))
            r.text += isoTable(cam);
        return r;
    }
    if (!o.reportDir.empty()) {
        prepareOutputDirectory(o.reportDir);
        writeReportTables(o.reportDir, cams);
        const PlotsWritten plots = plotReport(o.reportDir);
        r.pngs = plots.pngs;
        r.notes = plots.notes;
        const std::string report = reportText(cams, path, seconds, plots.pngs);
        writeNewText(o.reportDir + "/report.md",
                     "# What darktable's measured cameras say about Eq. 5\n\n" + report);
        r.text = report;
        return r;
    }
    const std::string verdict = o.verdict;
    if (verdict != "all" && verdict != "good" && verdict != "rough" && verdict != "refused" &&
        verdict != "usable")
        throw std::runtime_error("--verdict must be all, good, rough, usable or refused (got '" + verdict +
                                 "')");
    r.text = kCatalogueHeader;
    int listed = 0;
    for (const CameraNoiseProfile& cam : cams) {
        const bool show = verdict == "all" || (verdict == "usable" && cam.usable()) ||
                          (verdict == "good" && cam.verdict == CAMERA_PROFILE_GOOD) ||
                          (verdict == "rough" && cam.verdict == CAMERA_PROFILE_ROUGH) ||
                          (verdict == "refused" && cam.verdict == CAMERA_PROFILE_REFUSED);
        if (show) {
            r.text += catalogueLine(cam) + "\n";
            ++listed;
        }
    }
    r.text += cv::format("%d of %zu cameras listed (%s), read and fitted in %.2f s\n", listed, cams.size(),
                         path.c_str(), seconds);
    return r;
}

} // namespace rawgment_apps
