// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Real cameras (camera_profiles topic): darktable's measured noise profiles fitted to Eq. 5, the camera
// catalogue, camera draws, and the one loader that takes a model from any file the project reads.
#include "camera_profiles_detail.hpp"
#include "precomp.hpp"
#include "random.hpp"
#include "raw_io_detail.hpp"

#include <opencv2/rawgment/camera_profiles.hpp>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <numeric>
#include <set>

namespace cv {
namespace rawgment {

String cameraProfileVerdictName(int verdict)
{
    switch (verdict) {
    case CAMERA_PROFILE_GOOD:
        return "GOOD";
    case CAMERA_PROFILE_ROUGH:
        return "ROUGH";
    case CAMERA_PROFILE_REFUSED:
        return "REFUSED";
    default:
        CV_Error(Error::StsBadArg,
                 format("cameraProfileVerdictName: %d is not a CameraProfileVerdict", verdict));
    }
}

void DarktableImportParams::validate() const
{
    const auto check = [](bool ok, const char* what, double v, const char* range) {
        if (!ok)
            CV_Error(Error::StsBadArg,
                     format("DarktableImportParams: %s = %g must lie in %s", what, v, range));
    };
    check(haarVarianceRatio > 0 && haarVarianceRatio <= 1, "haarVarianceRatio", haarVarianceRatio, "(0, 1]");
    check(offsetReferenceLevel > 0 && offsetReferenceLevel < 1, "offsetReferenceLevel", offsetReferenceLevel,
          "(0, 1)");
    check(goodMedianSlopeResidual > 0 && goodMedianSlopeResidual <= goodWorstSlopeResidual,
          "goodMedianSlopeResidual", goodMedianSlopeResidual, "(0, goodWorstSlopeResidual]");
    check(std::isfinite(goodWorstSlopeResidual), "goodWorstSlopeResidual", goodWorstSlopeResidual,
          "(0, inf)");
    check(goodWorstOffsetResidual > 0 && std::isfinite(goodWorstOffsetResidual), "goodWorstOffsetResidual",
          goodWorstOffsetResidual, "(0, inf)");
    check(goodMinIsos >= 2, "goodMinIsos", goodMinIsos, "[2, inf)");
}

String CameraNoiseProfile::name() const
{
    return maker + " " + model;
}

NoiseModel CameraNoiseProfile::modelFor(const RawFormat& format) const
{
    if (!usable())
        CV_Error(Error::StsBadArg, "camera '" + name() + "' is REFUSED: " + reason);
    format.validate();
    // Green's range: the catalogue takes green's profile, which darktable (and darktableNoiseProfiles())
    // normalise by the green sites' own range; the mean of all four sites put a line 3e-5 off where the
    // sites' black levels differ.
    const double r = detail::rangeOfColourPlane(format, 1);
    NoiseModel m(noise.alpha * r, noise.sigmaD2 * r * r, noise.sigmaR2 * r * r);
    m.baseIso = noise.baseIso;
    // The augmentation follows what darktable measured at each ISO (NoiseModel::measuredLines); Eq. 5
    // stays the summary and the trend beyond the measured ISOs. An ISO measured twice takes the mean of its
    // two lines; a negative measured offset (a fit's intercept below zero, never a variance) is taken as 0;
    // an inconsistent profile is left out.
    for (size_t i = 0; i < isos.size();) {
        size_t j = i;
        double slope = 0, offset = 0, n = 0;
        for (; j < isos.size() && isos[j].iso == isos[i].iso; ++j)
            if (!isos[j].inconsistent) {
                slope += isos[j].slope;
                offset += isos[j].offset;
                ++n;
            }
        if (n == 0) { // only failed profiles at this ISO: its line comes from its neighbours
            i = j;
            continue;
        }
        MeasuredNoiseLine line;
        line.gain = isos[i].gain;
        line.iso = isos[i].iso;
        line.line.a = slope / n * r;
        line.line.b = std::max(offset / n, 0.0) * r * r;
        m.measuredLines.push_back(line);
        i = j;
    }
    m.validate();
    return m;
}

namespace {

//! The smallest shot slope (of the white level) a measured profile may have: a full well of 1e12 electrons.
constexpr double MIN_SHOT_SLOPE = 1e-12;

struct MeasuredProfile
{
    double iso = 0;
    double a[3] = {0, 0, 0};
    double b[3] = {0, 0, 0};
};

//! The profiles of one model entry; throws naming the profile's place on a malformed one.
std::vector<MeasuredProfile> readProfiles(const FileNode& modelNode, const String& place, int& skipped)
{
    std::vector<MeasuredProfile> profiles;
    int k = 0;
    for (const FileNode& p : modelNode["profiles"]) {
        const String where = place + format(".profiles[%d]", k++);
        try {
            if (!p.isMap())
                CV_Error(Error::StsParseError, "expected a map");
            rejectUnknownKeys(p, {"name", "iso", "a", "b", "skip", "comment"});
            if (detail::readOptionalFlagField(p, "skip", false)) {
                ++skipped;
                continue;
            }
            MeasuredProfile m;
            m.iso = detail::readRealField(p, "iso");
            const std::vector<double> a = detail::readRealList(p, "a", 3),
                                      b = detail::readRealList(p, "b", 3);
            for (int c = 0; c < 3; ++c) {
                m.a[c] = a[size_t(c)];
                m.b[c] = b[size_t(c)];
                if (!std::isfinite(m.a[c]) || !std::isfinite(m.b[c]))
                    CV_Error(Error::StsParseError, format("colour %d has a non-finite a or b", c));
                // A shot slope is one over the electrons of the full scale: below MIN_SHOT_SLOPE it would
                // take a trillion electrons (darktable's measured slopes are above 2e-7), and a denormal
                // one overflows the fit's sums to NaN or zero.
                if (m.a[c] > 0 && m.a[c] < MIN_SHOT_SLOPE)
                    CV_Error(Error::StsParseError,
                             format("colour %d has a shot slope a = %g, below %g: no sensor has a full well "
                                    "of 1e12 electrons",
                                    c, m.a[c], MIN_SHOT_SLOPE));
            }
            if (!(std::isfinite(m.iso) && m.iso > 0))
                CV_Error(Error::StsParseError, format("ISO %g must be finite and > 0", m.iso));
            profiles.push_back(m);
        } catch (const Exception& e) {
            CV_Error(Error::StsParseError, where + ": " + e.err);
        }
    }
    return profiles;
}

/** sigma_d^2, sigma_r^2 >= 0 minimising sum w (g^2 sd + sr - b)^2: the unconstrained solution when it is
 * feasible, else the best of the two faces and the origin (the problem is convex, so that is optimal). */
Vec2d fitOffsets(const std::vector<double>& g2, const std::vector<double>& b, const std::vector<double>& w)
{
    double s00 = 0, s01 = 0, s11 = 0, t0 = 0, t1 = 0;
    for (size_t k = 0; k < b.size(); ++k) {
        s00 += w[k] * g2[k] * g2[k];
        s01 += w[k] * g2[k];
        s11 += w[k];
        t0 += w[k] * g2[k] * b[k];
        t1 += w[k] * b[k];
    }
    const auto cost = [&](Vec2d s) {
        double c = 0;
        for (size_t k = 0; k < b.size(); ++k)
            c += w[k] * (g2[k] * s[0] + s[1] - b[k]) * (g2[k] * s[0] + s[1] - b[k]);
        return c;
    };
    std::vector<Vec2d> candidates = {Vec2d(std::max(0.0, t0 / s00), 0), Vec2d(0, std::max(0.0, t1 / s11)),
                                     Vec2d(0, 0)};
    const double det = s00 * s11 - s01 * s01;
    if (det > 1e-12 * s00 * s11) {
        const Vec2d free((t0 * s11 - t1 * s01) / det, (s00 * t1 - s01 * t0) / det);
        if (free[0] >= 0 && free[1] >= 0)
            return free;
    }
    Vec2d best = candidates[0];
    for (const Vec2d& c : candidates)
        if (cost(c) < cost(best))
            best = c;
    return best;
}

void judge(CameraNoiseProfile& cam, const DarktableImportParams& params)
{
    std::vector<String> rough;
    if (!(cam.medianSlopeResidual <= params.goodMedianSlopeResidual))
        rough.push_back(format("median shot-slope residual %.0f%% > %.0f%%", 100 * cam.medianSlopeResidual,
                               100 * params.goodMedianSlopeResidual));
    if (!(cam.worstSlopeResidual <= params.goodWorstSlopeResidual))
        rough.push_back(format("shot slope %.0f%% off at ISO %g (> %.0f%%)", 100 * cam.worstSlopeResidual,
                               cam.worstSlopeIso, 100 * params.goodWorstSlopeResidual));
    if (!(cam.worstOffsetResidual <= params.goodWorstOffsetResidual))
        rough.push_back(format("offset %.0f%% off at ISO %g (> %.0f%%)", 100 * cam.worstOffsetResidual,
                               cam.worstOffsetIso, 100 * params.goodWorstOffsetResidual));
    std::set<double> distinct;
    int fitted = 0;
    for (const CameraIsoFit& f : cam.isos)
        if (f.fitted()) {
            distinct.insert(f.iso);
            ++fitted;
        }
    if (int(distinct.size()) < params.goodMinIsos)
        rough.push_back(format("%d ISOs (< %d)", int(distinct.size()), params.goodMinIsos));
    if (2 * cam.negativeOffsets > fitted)
        rough.push_back(format("negative offsets at %d of %d ISOs", cam.negativeOffsets, fitted));
    cam.verdict = rough.empty() ? CAMERA_PROFILE_GOOD : CAMERA_PROFILE_ROUGH;
    for (const String& r : rough)
        cam.reason += (cam.reason.empty() ? "" : "; ") + r;
}

//! The settings of the ISOs of profiles by increasing ISO; an ISO measured twice is taken at its mean slope.
IsoSettings isoSettingsOf(const std::vector<const MeasuredProfile*>& profiles)
{
    std::vector<double> isos, slopes;
    for (size_t i = 0; i < profiles.size();) {
        size_t j = i;
        double sum = 0;
        for (; j < profiles.size() && profiles[j]->iso == profiles[i]->iso; ++j)
            sum += profiles[j]->a[1];
        isos.push_back(profiles[i]->iso);
        slopes.push_back(sum / double(j - i));
        i = j;
    }
    return classifyIsoSettings(isos, slopes);
}

//! Whether no colour's shot slope is negative (CameraIsoFit::inconsistent); 0 is a colour left unmeasured.
bool hasConsistentColours(const MeasuredProfile& p)
{
    return p.a[0] >= 0 && p.a[2] >= 0;
}

//! The scale an ISO's offset is weighted and its residual judged by: |b| + a x_ref.
double offsetScale(const CameraIsoFit& f, const DarktableImportParams& params)
{
    return std::abs(f.offset) + f.slope * params.offsetReferenceLevel;
}

/* The profiles with a positive green shot slope, by ISO (the others counted as skipped), and those of them
 * whose colours are consistent, with their distinct ISOs. Two profiles at one ISO (19 of darktable's 4.2.1
 * cameras have some) are two measurements of it: both are fitted. */
struct UsableProfiles
{
    std::vector<const MeasuredProfile*> usable, consistent;
    std::set<double> distinct;
};

UsableProfiles usableProfiles(CameraNoiseProfile& cam, const std::vector<MeasuredProfile>& profiles)
{
    UsableProfiles u;
    for (const MeasuredProfile& p : profiles) {
        if (!(p.a[1] > 0)) {
            ++cam.skippedProfiles;
            continue;
        }
        u.usable.push_back(&p);
    }
    const auto byIso = [](const MeasuredProfile* x, const MeasuredProfile* y) { return x->iso < y->iso; };
    std::stable_sort(u.usable.begin(), u.usable.end(), byIso);
    // A colour whose shot slope is negative is a failed fit, not a noise.
    for (const MeasuredProfile* p : u.usable)
        if (hasConsistentColours(*p)) {
            u.consistent.push_back(p);
            u.distinct.insert(p->iso);
        }
    cam.inconsistentProfiles = static_cast<int>(u.usable.size() - u.consistent.size());
    return u;
}

// One ISO's measured line in the model's units (green, darktable's Haar ratio `c` taken out) and its figures.
CameraIsoFit isoFitOf(const MeasuredProfile& p, double baseIso, const IsoSettings& settings, double c)
{
    CameraIsoFit f;
    f.iso = p.iso;
    f.gain = p.iso / baseIso;
    f.slope = p.a[1] / c;
    f.offset = p.b[1] / c;
    f.expanded = settings.expanded.count(p.iso) > 0;
    const auto digital = settings.digital.find(p.iso);
    f.rawIso = digital == settings.digital.end() ? 0 : digital->second;
    f.inconsistent = !hasConsistentColours(p);
    double lo = HUGE_VAL, hi = 0;
    for (int k = 0; k < 3; ++k)
        if (p.a[k] > 0) {
            lo = std::min(lo, p.a[k]);
            hi = std::max(hi, p.a[k]);
        }
    f.colourSpread = hi / lo;
    for (int k = 0; k < 2; ++k)
        f.colourSlopeRatios[k] = p.a[2 * k] > 0 ? p.a[2 * k] / p.a[1] : 0;
    return f;
}

// Each ISO's residuals against the fitted model, and the verdict's figures over the fitted settings.
void measureResiduals(CameraNoiseProfile& cam, const DarktableImportParams& params)
{
    std::vector<double> slopeResiduals, spreads;
    const CameraIsoFit* previous = nullptr; // the last fitted ISO
    for (size_t k = 0; k < cam.isos.size(); ++k) {
        CameraIsoFit& f = cam.isos[k];
        const NoiseLine line = cam.noise.lineAtGain(f.gain);
        f.slopeResidual = (line.a - f.slope) / f.slope;
        f.offsetResidual = (line.b - f.offset) / offsetScale(f, params);
        // The verdict's figures are over the fitted (analog, consistent) settings.
        if (!f.fitted())
            continue;
        slopeResiduals.push_back(std::abs(f.slopeResidual));
        spreads.push_back(f.colourSpread);
        if (std::abs(f.slopeResidual) > cam.worstSlopeResidual) {
            cam.worstSlopeResidual = std::abs(f.slopeResidual);
            cam.worstSlopeIso = f.iso;
        }
        if (std::abs(f.offsetResidual) > cam.worstOffsetResidual) {
            cam.worstOffsetResidual = std::abs(f.offsetResidual);
            cam.worstOffsetIso = f.iso;
        }
        cam.negativeOffsets += f.offset < 0;
        if (previous && f.iso > previous->iso && f.slope < previous->slope)
            cam.monotoneSlope = false;
        previous = &f;
    }
    cam.medianSlopeResidual = medianOf(slopeResiduals);
    cam.medianColourSpread = medianOf(spreads);
}

//! Fits one camera from its measured profiles; sets REFUSED with the reason when it cannot.
void fitCamera(CameraNoiseProfile& cam, const std::vector<MeasuredProfile>& profiles,
               const DarktableImportParams& params)
{
    const double c = params.haarVarianceRatio;
    cam.haarVarianceRatio = c;
    const UsableProfiles u = usableProfiles(cam, profiles);
    if (u.distinct.size() < 2) {
        cam.verdict = CAMERA_PROFILE_REFUSED;
        cam.reason = u.usable.empty() ? String("no profile with a positive green shot slope")
                     : u.consistent.empty()
                         ? String("no profile without a negative colour shot slope")
                         : format("a single usable ISO (%g): the read noise before and after the "
                                  "gain cannot be told apart",
                                  u.consistent[0]->iso);
        return;
    }
    const IsoSettings settings = isoSettingsOf(u.consistent);
    cam.expandedIsos = static_cast<int>(settings.expanded.size());
    cam.digitalIsos = static_cast<int>(settings.digital.size());
    double baseIso = 0;
    for (const MeasuredProfile* p : u.consistent)
        if (!settings.expanded.count(p->iso) && !settings.digital.count(p->iso)) {
            baseIso = p->iso;
            break;
        }
    std::vector<double> g, a, b, g2, w;
    for (const MeasuredProfile* p : u.usable) {
        const CameraIsoFit f = isoFitOf(*p, baseIso, settings, c);
        cam.isos.push_back(f);
        // Eq. 5 describes the analog settings: an expanded or digital one is measured (and followed) but not
        // fitted, an inconsistent one neither.
        if (!f.fitted())
            continue;
        g.push_back(f.gain);
        a.push_back(f.slope);
        b.push_back(f.offset);
        g2.push_back(f.gain * f.gain);
        const double scale = offsetScale(f, params);
        w.push_back(1 / (scale * scale));
    }
    // alpha minimises the relative slope residuals: sum ((g alpha - a) / a)^2.
    double num = 0, den = 0;
    for (size_t k = 0; k < g.size(); ++k) {
        num += g[k] / a[k];
        den += g[k] * g[k] / (a[k] * a[k]);
    }
    const double alpha = num / den;
    const Vec2d offsets = fitOffsets(g2, b, w);
    // NaN passes every '>' bound of the verdict: a fit that is not finite is refused here.
    if (!(std::isfinite(alpha) && alpha > 0 && std::isfinite(offsets[0]) && std::isfinite(offsets[1]))) {
        cam.verdict = CAMERA_PROFILE_REFUSED;
        cam.reason = format("the fit is not finite and positive (alpha %g, sigma_d^2 %g, sigma_r^2 %g)",
                            alpha, offsets[0], offsets[1]);
        return;
    }
    cam.noise = NoiseModel(alpha, offsets[0], offsets[1]);
    cam.noise.baseIso = baseIso;
    measureResiduals(cam, params);
    judgeProfileDemosaic(cam);
    if (cam.negativeOffsets == int(g.size())) {
        cam.verdict = CAMERA_PROFILE_REFUSED;
        cam.reason =
            format("offsets below zero at all %d ISOs: the read noise was not measured", int(g.size()));
        return;
    }
    if (cam.noise.sigmaD2 == 0 && cam.noise.sigmaR2 == 0) {
        cam.verdict = CAMERA_PROFILE_REFUSED;
        cam.reason = "the offsets fit no read noise at all (sigma_d^2 and sigma_r^2 both zero)";
        return;
    }
    judge(cam, params);
}

/** The name with each control character written as an escape ("\\n", "\\x01"), so that a catalogue line or a
 * CSV row never breaks where the file put a newline; counts them in `controls`. */
String printableName(const String& name, int& controls)
{
    String out;
    for (char ch : name) {
        const unsigned char u = static_cast<unsigned char>(ch);
        if (u >= 0x20 && u != 0x7F) {
            out += ch;
            continue;
        }
        ++controls;
        out += u == '\n'   ? String("\\n")
               : u == '\r' ? String("\\r")
               : u == '\t' ? String("\\t")
                           : format("\\x%02x", u);
    }
    return out;
}

String normalisedName(const String& name)
{
    String out;
    for (char ch : name) {
        const bool space = std::isspace(static_cast<unsigned char>(ch)) != 0;
        if (space && (out.empty() || out.back() == ' '))
            continue;
        out += space ? ' ' : static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    }
    while (!out.empty() && out.back() == ' ')
        out.pop_back();
    return out;
}

size_t editDistance(const String& x, const String& y)
{
    std::vector<size_t> row(y.size() + 1);
    std::iota(row.begin(), row.end(), size_t(0));
    for (size_t i = 1; i <= x.size(); ++i) {
        size_t diagonal = row[0];
        row[0] = i;
        for (size_t j = 1; j <= y.size(); ++j) {
            const size_t up = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (x[i - 1] == y[j - 1] ? 0 : 1)});
            diagonal = up;
        }
    }
    return row[y.size()];
}

} // namespace

std::vector<CameraNoiseProfile> readCameraProfiles(const String& path, const DarktableImportParams& params)
{
    params.validate();
    const String where = "readCameraProfiles: '" + path + "'";
    FileStorage fs = openFileStorageForReading(path, "darktable noise profiles");
    std::vector<CameraNoiseProfile> cameras;
    const FileNode root = fs.root();
    try {
        rejectUnknownKeys(root, {"version", "noiseprofiles"});
        if (!root["noiseprofiles"].isSeq())
            CV_Error(Error::StsParseError, "expected a list 'noiseprofiles'");
    } catch (const Exception& e) {
        CV_Error(Error::StsParseError, where + ": " + e.err);
    }
    int i = 0;
    for (const FileNode& makerNode : root["noiseprofiles"]) {
        const String makerPlace = format("noiseprofiles[%d]", i++);
        try {
            if (!makerNode.isMap())
                CV_Error(Error::StsParseError, "expected a map");
            rejectUnknownKeys(makerNode, {"maker", "models", "comment"});
            if (!makerNode["maker"].isString() || !makerNode["models"].isSeq())
                CV_Error(Error::StsParseError, "a maker entry needs a string 'maker' and a list 'models'");
        } catch (const Exception& e) {
            CV_Error(Error::StsParseError, where + ": " + makerPlace + ": " + e.err);
        }
        int j = 0;
        for (const FileNode& modelNode : makerNode["models"]) {
            CameraNoiseProfile cam;
            cam.maker = String(makerNode["maker"]);
            cam.place = makerPlace + format(".models[%d]", j++);
            try {
                if (!modelNode.isMap())
                    CV_Error(Error::StsParseError, "expected a map");
                rejectUnknownKeys(modelNode, {"model", "comment", "profiles"});
                if (!modelNode["model"].isString() || !modelNode["profiles"].isSeq())
                    CV_Error(Error::StsParseError,
                             "a model entry needs a string 'model' and a list 'profiles'");
                cam.model = String(modelNode["model"]);
                const std::vector<MeasuredProfile> profiles =
                    readProfiles(modelNode, cam.place, cam.skippedProfiles);
                fitCamera(cam, profiles, params);
            } catch (const Exception& e) {
                // One malformed camera is refused, naming its place; the others are still read.
                CameraNoiseProfile refused;
                refused.maker = cam.maker;
                refused.model = cam.model;
                refused.place = cam.place;
                cam = refused;
                cam.verdict = CAMERA_PROFILE_REFUSED;
                cam.reason =
                    "malformed: " +
                    (e.err.compare(0, cam.place.size(), cam.place) == 0 ? e.err : cam.place + ": " + e.err);
            }
            int controls = 0;
            cam.maker = printableName(cam.maker, controls);
            cam.model = printableName(cam.model, controls);
            if (controls > 0) {
                cam.verdict = CAMERA_PROFILE_REFUSED;
                cam.reason = format("its name holds %d control character%s (shown escaped): a name that "
                                    "cannot be typed or printed on one line cannot be selected",
                                    controls, controls == 1 ? "" : "s");
            }
            cameras.push_back(cam);
        }
    }
    std::set<String> names;
    for (CameraNoiseProfile& cam : cameras)
        if (!names.insert(normalisedName(cam.name())).second && cam.usable()) {
            cam.verdict = CAMERA_PROFILE_REFUSED;
            cam.reason = "its name repeats an earlier entry's: cameras are selected by name";
        }
    return cameras;
}

CameraNoiseProfile findCameraProfile(const std::vector<CameraNoiseProfile>& cameras, const String& name)
{
    const String wanted = normalisedName(name);
    for (const CameraNoiseProfile& cam : cameras)
        if (normalisedName(cam.name()) == wanted) {
            if (!cam.usable())
                CV_Error(Error::StsBadArg, "camera '" + cam.name() + "' is REFUSED: " + cam.reason);
            return cam;
        }
    std::vector<std::pair<size_t, String>> near;
    for (const CameraNoiseProfile& cam : cameras)
        near.emplace_back(editDistance(wanted, normalisedName(cam.name())), cam.name());
    std::sort(near.begin(), near.end());
    String list;
    for (size_t k = 0; k < near.size() && k < 5; ++k)
        list += (k ? "', '" : "'") + near[k].second + (k + 1 == std::min<size_t>(near.size(), 5) ? "'" : "");
    CV_Error(Error::StsBadArg, "no camera named '" + name + "' among " + std::to_string(cameras.size()) +
                                   " cameras" + (list.empty() ? String() : "; the closest are " + list));
}

std::vector<CameraNoiseProfile> selectCameraProfiles(const std::vector<CameraNoiseProfile>& cameras,
                                                     const String& selection)
{
    const String word = normalisedName(selection);
    std::vector<CameraNoiseProfile> chosen;
    if (word == "good" || word == "usable") {
        for (const CameraNoiseProfile& cam : cameras)
            if (cam.verdict == CAMERA_PROFILE_GOOD || (word == "usable" && cam.usable()))
                chosen.push_back(cam);
        if (chosen.empty())
            CV_Error(Error::StsBadArg, "camera selection '" + selection + "': no camera has that verdict");
        return chosen;
    }
    // Names are split at commas, but a camera's own name may hold one ("Foo, Inc. X"): at each place
    // the longest run of comma-separated pieces that names a camera is taken, and a piece that starts
    // no name is looked up alone (for the error with the closest names).
    std::vector<String> pieces;
    for (size_t start = 0; start <= selection.size();) {
        const size_t comma = std::min(selection.find(',', start), selection.size());
        pieces.push_back(selection.substr(start, comma - start));
        start = comma + 1;
    }
    std::set<String> names;
    for (const CameraNoiseProfile& cam : cameras)
        names.insert(normalisedName(cam.name()));
    for (size_t i = 0; i < pieces.size();) {
        size_t end = i + 1;
        for (size_t j = pieces.size(); j > i + 1; --j) {
            String joined = pieces[i];
            for (size_t k = i + 1; k < j; ++k)
                joined += "," + pieces[k];
            if (names.count(normalisedName(joined))) {
                end = j;
                break;
            }
        }
        String one = pieces[i];
        for (size_t k = i + 1; k < end; ++k)
            one += "," + pieces[k];
        one.erase(0, one.find_first_not_of(" \t"));
        one.erase(one.find_last_not_of(" \t") + 1);
        if (!one.empty())
            chosen.push_back(findCameraProfile(cameras, one));
        i = end;
    }
    if (chosen.empty())
        CV_Error(Error::StsBadArg, "camera selection '" + selection + "' names no camera");
    return chosen;
}

int drawCameraIndex(int count, uint64 seed)
{
    if (count < 1)
        CV_Error(Error::StsBadArg,
                 format("drawCameraIndex: %d cameras to draw from; need at least one", count));
    const uint64_t key = detail::stepKey(seed, detail::RandomStream::CAMERA_DRAW);
    const std::array<uint32_t, 4> words =
        detail::philox4x32({0, 0, 0, 0}, {uint32_t(key), uint32_t(key >> 32)});
    // Multiply-shift maps 32 uniform bits onto [0, count) with a bias below count / 2^32 (2e-7 for
    // darktable's 374 cameras).
    return static_cast<int>((uint64_t(words[0]) * static_cast<uint64_t>(count)) >> 32);
}

String darktableProfilesPath()
{
    const char* chosen = std::getenv("RAWGMENT_DARKTABLE_PROFILES");
    if (chosen && *chosen)
        return chosen;
    const char* cache = std::getenv("RAWGMENT_CACHE_DIR");
    const char* xdg = std::getenv("XDG_CACHE_HOME");
    const char* home = std::getenv("HOME");
    const String folder = cache && *cache ? String(cache)
                          : xdg && *xdg   ? String(xdg) + "/rawgment"
                          : home && *home ? String(home) + "/.cache/rawgment"
                                          : String();
    if (!folder.empty() && pathExists(folder + "/darktable/noiseprofiles.json"))
        return folder + "/darktable/noiseprofiles.json";
    if (pathExists("/usr/share/darktable/noiseprofiles.json"))
        return "/usr/share/darktable/noiseprofiles.json";
    return String();
}

int noiseModelFileKind(const String& path)
{
    FileStorage fs = openFileStorageForReading(path, "noise model");
    if (detail::lowerExtensionOf(path) == ".json" && !fs.root()["noiseprofiles"].empty())
        return DARKTABLE_PROFILE_FILE;
    return fs["android_noise_profile"].empty() ? NOISE_MODEL_FILE : ANDROID_PROFILE_FILE;
}

NoiseModel noiseModelFromAndroidFile(const String& path, const RawFormat& format)
{
    FileStorage fs = openFileStorageForReading(path, "Android noise profile");
    const FileNode node = fs["android_noise_profile"];
    AndroidNoiseProfile profile;
    double baseIso = 0;
    try {
        // A model beside the profile (a failed calibration's noise_model, say) would be ignored, and with
        // it its failed_calibration mark: the file holds the profile alone.
        rejectUnknownKeys(fs.root(), {"android_noise_profile"});
        if (!node.isMap())
            CV_Error(Error::StsParseError, "expected a map 'android_noise_profile'");
        rejectUnknownKeys(node, {"comment", "base_iso", "A", "B", "C", "D"});
        baseIso = detail::readRealField(node, "base_iso");
        Vec4d* fields[4] = {&profile.A, &profile.B, &profile.C, &profile.D};
        const char* names[4] = {"A", "B", "C", "D"};
        for (int f = 0; f < 4; ++f) {
            const std::vector<double> v = detail::readRealList(node, names[f], 4);
            *fields[f] = Vec4d(v[0], v[1], v[2], v[3]);
        }
        return noiseModelFromAndroid(profile, format, baseIso);
    } catch (const Exception& e) {
        CV_Error(e.code, "noiseModelFromAndroidFile: '" + path + "': " + e.err);
    }
}

NoiseModel loadAnyNoiseModel(const String& path, const String& camera, const RawFormat& format,
                             bool acceptFailedCalibration)
{
    const int kind = noiseModelFileKind(path);
    if (kind == DARKTABLE_PROFILE_FILE) {
        if (camera.empty())
            CV_Error(Error::StsBadArg, "'" + path +
                                           "' is a darktable noise-profile file of many cameras: choose one "
                                           "(--camera in the apps; rawgment_cameras lists them)");
        return findCameraProfile(readCameraProfiles(path), camera).modelFor(format);
    }
    if (!camera.empty())
        CV_Error(Error::StsBadArg, "a camera ('" + camera + "') is chosen, but '" + path +
                                       "' is not a darktable noise-profile file");
    if (kind == ANDROID_PROFILE_FILE)
        return noiseModelFromAndroidFile(path, format);
    return NoiseModel::load(path, acceptFailedCalibration);
}

} // namespace rawgment
} // namespace cv
