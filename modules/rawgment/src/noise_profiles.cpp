// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The noise model in the forms other tools read (raw_io topic): the DNG NoiseProfile tag (51041), read
// from a DNG's IFDs because LibRaw 0.20 parses but does not expose it; darktable's noise-profile JSON;
// the Android camera tests' form.
#include "raw_io_detail.hpp"

#include <opencv2/rawgment/raw_io.hpp>

#include <algorithm>
#include <cstring>
#include <memory>
#include <set>
#include <sstream>
#include <vector>

namespace cv {
namespace rawgment {

namespace {

//! DNG colour plane (CFAPlaneColor 0, 1, 2) of a CFA site.
int colourPlaneOf(CfaChannel channel)
{
    return channel == CFA_R ? 0 : (channel == CFA_B ? 2 : 1);
}

//! Bounded reads of a TIFF file of either byte order: every offset is checked against the file's size,
//! so a hostile file gives an error naming it, never a read outside it.
class TiffFile
{
public:
    explicit TiffFile(const String& path) : path_(path)
    {
        try {
            file_.reset(new detail::RegularFileForReading(path, "RAW file"));
        } catch (const Exception&) {
            fail("cannot be opened");
        }
        size_ = static_cast<uint64_t>(file_->size());
        char order[2] = {0, 0};
        bytes(0, order, 2);
        if (order[0] == 'I' && order[1] == 'I')
            bigEndian_ = false;
        else if (order[0] == 'M' && order[1] == 'M')
            bigEndian_ = true;
        else
            fail("is not a TIFF-based file");
        if (u16(2) != 42)
            fail("has a TIFF header without the number 42");
    }
    bool bigEndian() const { return bigEndian_; }
    uint16_t u16(uint64_t at) { return static_cast<uint16_t>(unsignedAt<2>(at)); }
    uint32_t u32(uint64_t at) { return static_cast<uint32_t>(unsignedAt<4>(at)); }
    double f64(uint64_t at)
    {
        const uint64_t v = unsignedAt<8>(at);
        double d;
        std::memcpy(&d, &v, sizeof(d));
        return d;
    }
    [[noreturn]] void fail(const String& why) const
    {
        CV_Error(Error::StsParseError, "readRaw: '" + path_ + "' " + why);
    }
    //! The values of the IFD entry at `entry` as numbers (rationals as numerator, denominator pairs).
    std::vector<double> values(uint64_t entry)
    {
        const uint16_t tag = u16(entry), type = u16(entry + 2);
        const uint32_t count = u32(entry + 4);
        static const int sizes[13] = {0, 1, 1, 2, 4, 8, 1, 1, 2, 4, 8, 4, 8};
        if (type < 1 || type > 12 || count > 64)
            fail(format("has tag %d of type %d with %u values; a colour tag has at most 64 values of a "
                        "TIFF type 1 to 12",
                        int(tag), int(type), count));
        const uint64_t size = uint64_t(sizes[type]) * count;
        const uint64_t at = size <= 4 ? entry + 8 : u32(entry + 8);
        std::vector<double> v;
        for (uint32_t k = 0; k < count; ++k) {
            const uint64_t p = at + uint64_t(sizes[type]) * k;
            switch (type) {
            case 3:
                v.push_back(u16(p));
                break;
            case 8:
                v.push_back(static_cast<int16_t>(u16(p)));
                break;
            case 4:
                v.push_back(u32(p));
                break;
            case 9:
                v.push_back(static_cast<int32_t>(u32(p)));
                break;
            case 5:
                v.push_back(u32(p));
                v.push_back(u32(p + 4));
                break;
            case 10:
                v.push_back(static_cast<int32_t>(u32(p)));
                v.push_back(static_cast<int32_t>(u32(p + 4)));
                break;
            case 11: {
                const uint32_t bits = u32(p);
                float f;
                std::memcpy(&f, &bits, sizeof(f));
                v.push_back(f);
                break;
            }
            case 12:
                v.push_back(f64(p));
                break;
            default:
                v.push_back(static_cast<double>(unsignedAt<1>(p)));
                break;
            }
        }
        return v;
    }

private:
    void bytes(uint64_t at, void* out, uint64_t n)
    {
        if (at > size_ || n > size_ - at)
            fail(format("is truncated: a TIFF field at byte %llu lies beyond its end (%llu bytes)",
                        static_cast<unsigned long long>(at), static_cast<unsigned long long>(size_)));
        if (!detail::readFullyAt(file_->fd(), out, static_cast<size_t>(n), static_cast<long long>(at), path_,
                                 "readRaw"))
            fail("could not be read");
    }
    //! The unsigned integer of `Bytes` bytes at `at`, in the file's byte order.
    template <int Bytes> uint64_t unsignedAt(uint64_t at)
    {
        unsigned char b[Bytes];
        bytes(at, b, Bytes);
        uint64_t v = 0;
        for (int k = 0; k < Bytes; ++k)
            v |= uint64_t(b[bigEndian_ ? k : Bytes - 1 - k]) << (8 * (Bytes - 1 - k));
        return v;
    }
    String path_;
    std::unique_ptr<detail::RegularFileForReading> file_;
    uint64_t size_ = 0;
    bool bigEndian_ = false;
};

const uint16_t kTagSubIfds = 330;
const uint16_t kTagNoiseProfile = 51041;
const uint16_t kTypeLong = 4, kTypeDouble = 12, kTypeIfd = 13;

//! Searches one IFD for the NoiseProfile, queueing its SubIFDs; returns true when found.
bool searchIfd(TiffFile& tiff, uint64_t ifd, std::vector<uint64_t>& queue, std::vector<Vec2d>& profile)
{
    const uint16_t entries = tiff.u16(ifd);
    for (uint16_t i = 0; i < entries; ++i) {
        const uint64_t entry = ifd + 2 + 12ull * i;
        const uint16_t tag = tiff.u16(entry), type = tiff.u16(entry + 2);
        const uint32_t count = tiff.u32(entry + 4);
        if (tag == kTagSubIfds && (type == kTypeLong || type == kTypeIfd)) {
            if (count == 1)
                queue.push_back(tiff.u32(entry + 8));
            else
                for (uint32_t k = 0; k < count && k < 64; ++k)
                    queue.push_back(tiff.u32(tiff.u32(entry + 8) + 4ull * k));
        } else if (tag == kTagNoiseProfile) {
            if (type != kTypeDouble || (count != 2 && count != 6))
                tiff.fail(format("has a NoiseProfile tag of type %d with %u values; DNG requires 2 or 2 x 3 "
                                 "DOUBLE values",
                                 int(type), count));
            const uint64_t values = tiff.u32(entry + 8);
            for (uint32_t k = 0; k < count; k += 2)
                profile.emplace_back(tiff.f64(values + 8ull * k), tiff.f64(values + 8ull * (k + 1)));
            return true;
        }
    }
    return false;
}

} // namespace

namespace detail {

double rangeOfColourPlane(const RawFormat& format, int plane)
{
    // A monochrome frame's one plane stands for every colour a profile names (darktable's hold three).
    if (format.isMonochrome())
        return format.whiteLevel - format.blackLevel[0];
    double black = 0;
    int sites = 0;
    for (int site = 0; site < 4; ++site)
        if (colourPlaneOf(cfaChannelAt(format.pattern, site / 2, site % 2)) == plane) {
            black += format.blackLevel[site];
            ++sites;
        }
    return format.whiteLevel - black / sites;
}

//! Whether a regular file starts with a TIFF header of either byte order (DNG, NEF, ...).
static bool isTiffBased(const String& path)
{
    const RegularFileForReading file(path, "RAW file");
    char head[4] = {0, 0, 0, 0};
    return readFullyAt(file.fd(), head, 4, 0, path, "readRaw") &&
           ((head[0] == 'I' && head[1] == 'I' && head[2] == 42 && head[3] == 0) ||
            (head[0] == 'M' && head[1] == 'M' && head[2] == 0 && head[3] == 42));
}

bool isColorTag(int tag)
{
    static const int tags[] = {50721, 50722, 50723, 50724, 50725, 50726, 50727,
                               50728, 50729, 50778, 50779, 50964, 50965};
    return std::find(std::begin(tags), std::end(tags), tag) != std::end(tags);
}

std::vector<DngTag> readDngColorTags(const String& path)
{
    if (!isTiffBased(path))
        return {};
    TiffFile tiff(path);
    // DNG keeps its colour tags in IFD0.
    const uint64_t ifd = tiff.u32(4);
    const uint16_t entries = tiff.u16(ifd);
    std::vector<DngTag> tags;
    for (uint16_t i = 0; i < entries; ++i) {
        const uint64_t entry = ifd + 2 + 12ull * i;
        const int tag = tiff.u16(entry);
        if (!isColorTag(tag))
            continue;
        DngTag t;
        t.tag = tag;
        t.type = tiff.u16(entry + 2);
        t.count = static_cast<int>(tiff.u32(entry + 4));
        t.values = tiff.values(entry);
        try {
            t.validate("colour tag");
        } catch (const Exception& e) {
            tiff.fail("has an invalid " + e.err);
        }
        if (std::none_of(tags.begin(), tags.end(), [&](const DngTag& d) { return d.tag == tag; }))
            tags.push_back(t);
    }
    // ColorMatrix1 is what makes the others mean anything: without it the file states no colour.
    if (std::none_of(tags.begin(), tags.end(), [](const DngTag& d) { return d.tag == 50721; }))
        return {};
    std::sort(tags.begin(), tags.end(), [](const DngTag& a, const DngTag& b) { return a.tag < b.tag; });
    return tags;
}

//! The NoiseProfile pairs of a TIFF-based file (DNG), empty when it has none or is not TIFF-based.
std::vector<Vec2d> readDngNoiseProfile(const String& path)
{
    if (!isTiffBased(path))
        return {};
    TiffFile tiff(path);
    // IFD0 and the IFDs chained after it, then the SubIFDs they name. A hostile file's loops end at the
    // first revisit, and the search at 256 IFDs.
    std::vector<uint64_t> queue;
    std::set<uint64_t> chained;
    for (uint64_t ifd = tiff.u32(4); ifd != 0 && chained.size() < 256 && chained.insert(ifd).second;
         ifd = tiff.u32(ifd + 2 + 12ull * tiff.u16(ifd)))
        queue.push_back(ifd);
    std::vector<Vec2d> profile;
    std::set<uint64_t> searched;
    for (size_t k = 0; k < queue.size() && searched.size() < 256; ++k)
        if (searched.insert(queue[k]).second && searchIfd(tiff, queue[k], queue, profile))
            break;
    if (!profile.empty()) {
        try {
            checkDngNoiseProfile(profile, "the NoiseProfile tag");
        } catch (const Exception& e) {
            tiff.fail("has an invalid NoiseProfile: " + e.err);
        }
    }
    return profile;
}

double readExifIsoSpeed(const String& path)
{
    if (!isTiffBased(path))
        return 0;
    TiffFile tiff(path);
    const auto tagIn = [&](uint64_t ifd, uint16_t wanted, uint64_t& entry) {
        const uint16_t entries = tiff.u16(ifd);
        for (uint16_t i = 0; i < entries; ++i)
            if (tiff.u16(ifd + 2 + 12ull * i) == wanted) {
                entry = ifd + 2 + 12ull * i;
                return true;
            }
        return false;
    };
    uint64_t exifPointer = 0, iso = 0;
    if (!tagIn(tiff.u32(4), 34665, exifPointer))
        return 0;
    const uint64_t exif = tiff.u32(exifPointer + 8);
    // ISOSpeed (34867), else RecommendedExposureIndex (34866): one LONG each.
    for (uint16_t tag : {uint16_t(34867), uint16_t(34866)})
        if (tagIn(exif, tag, iso) && tiff.u16(iso + 2) == kTypeLong && tiff.u32(iso + 4) == 1)
            return tiff.u32(iso + 8);
    return 0;
}

void checkDngNoiseProfile(const std::vector<Vec2d>& profile, const char* what)
{
    if (profile.size() != 1 && profile.size() != 3)
        CV_Error(Error::StsBadArg,
                 format("%s: %d (S, O) pairs; a DNG NoiseProfile has 1 or 3 (red, green, blue)", what,
                        int(profile.size())));
    for (size_t k = 0; k < profile.size(); ++k)
        if (!(std::isfinite(profile[k][0]) && std::isfinite(profile[k][1]) && profile[k][0] > 0 &&
              profile[k][1] >= 0))
            CV_Error(Error::StsBadArg, format("%s: pair %d is (%g, %g); DNG requires S > 0 and O >= 0", what,
                                              int(k), profile[k][0], profile[k][1]));
}

} // namespace detail

void DngTag::validate(const char* what) const
{
    if (!detail::isColorTag(tag))
        CV_Error(Error::StsBadArg, format("%s: tag %d is not one of the DNG colour tags", what, tag));
    const bool rational = type == 5 || type == 10;
    if (type != 3 && type != 4 && !rational && type != 11 && type != 12)
        CV_Error(Error::StsBadArg,
                 format("%s %d: TIFF type %d is not SHORT, LONG, RATIONAL, SRATIONAL, FLOAT or "
                        "DOUBLE",
                        what, tag, type));
    if (count < 1 || count > 64 || values.size() != size_t(count) * (rational ? 2 : 1))
        CV_Error(Error::StsBadArg, format("%s %d: %zu values for a count of %d%s", what, tag, values.size(),
                                          count, rational ? " (rationals take two each)" : ""));
    const double lo = type == 10 ? -2147483648.0 : 0, hi = type == 3    ? 65535.0
                                                           : type == 10 ? 2147483647.0
                                                                        : 4294967295.0;
    for (size_t k = 0; k < values.size(); ++k) {
        const double v = values[k];
        if (type == 11 || type == 12) {
            if (!std::isfinite(v))
                CV_Error(Error::StsBadArg, format("%s %d: value %zu is not finite", what, tag, k));
            continue;
        }
        if (!(v == std::floor(v) && v >= lo && v <= hi) || (rational && k % 2 == 1 && v == 0))
            CV_Error(Error::StsBadArg,
                     format("%s %d: value %zu (%g) does not fit TIFF type %d%s", what, tag, k, v, type,
                            rational && k % 2 == 1 ? " (a denominator must not be 0)" : ""));
    }
}

std::vector<Vec2d> dngNoiseProfile(const NoiseModel& model, const RawFormat& format)
{
    format.validate();
    model.validate();
    const NoiseLine line = model.lineAtGain(format.gain);
    // A monochrome DNG has one colour plane, so one (S, O) pair: its colour plane is green's (CFA_W).
    std::vector<Vec2d> profile(format.isMonochrome() ? 1 : 3);
    for (size_t k = 0; k < profile.size(); ++k) {
        const double r = detail::rangeOfColourPlane(format, static_cast<int>(k));
        profile[k] = Vec2d(line.a / r, line.b / (r * r));
    }
    detail::checkDngNoiseProfile(profile, "dngNoiseProfile");
    return profile;
}

NoiseLine noiseLineFromDngProfile(const std::vector<Vec2d>& profile, const RawFormat& format,
                                  CfaChannel channel)
{
    detail::checkDngNoiseProfile(profile, "noiseLineFromDngProfile");
    format.validate();
    if (format.isMonochrome() != (channel == CFA_W))
        CV_Error(Error::StsBadArg,
                 cv::format("noiseLineFromDngProfile: channel %d of a %s format (CFA_W is the "
                            "only channel of a monochrome frame, and only of one)",
                            static_cast<int>(channel), cfaPatternName(format.pattern).c_str()));
    if (format.isMonochrome() && profile.size() != 1)
        CV_Error(Error::StsBadArg,
                 cv::format("noiseLineFromDngProfile: %d (S, O) pairs for a monochrome frame, which has one "
                            "colour plane and so one pair",
                            static_cast<int>(profile.size())));
    const int plane = colourPlaneOf(channel);
    const Vec2d so = profile.size() == 1 ? profile[0] : profile[static_cast<size_t>(plane)];
    const double r = detail::rangeOfColourPlane(format, plane);
    NoiseLine line;
    line.a = so[0] * r;
    line.b = so[1] * r * r;
    // S and O are finite, but S r or O r^2 need not be (S = 1e308 at a white level of 4095).
    if (!std::isfinite(line.a) || !std::isfinite(line.b))
        CV_Error(
            Error::StsBadArg,
            cv::format("noiseLineFromDngProfile: the pair (%g, %g) gives the line a = %g, b = %g at a range "
                       "of %g DN; a noise profile must give a finite line",
                       so[0], so[1], line.a, line.b, r));
    return line;
}

NoiseModel withDngNoiseProfileLine(const NoiseModel& model, const RawImage& image)
{
    model.validate();
    const char* what = "withDngNoiseProfileLine";
    if (image.noiseProfile.empty())
        CV_Error(Error::StsBadArg, cv::format("%s: the file has no NoiseProfile", what));
    if (!(image.iso > 0) || !(model.baseIso > 0))
        CV_Error(Error::StsBadArg,
                 cv::format("%s: the line's gain is ISO / baseIso, and %s", what,
                            image.iso > 0 ? "the model has no base ISO" : "the file states no ISO"));
    MeasuredNoiseLine measured;
    measured.gain = image.iso / model.baseIso;
    measured.iso = image.iso;
    // Green's line: the augmentation's one line per gain, as darktable's catalogue takes it.
    measured.line = noiseLineFromDngProfile(image.noiseProfile, image.format,
                                            image.format.isMonochrome() ? CFA_W : CFA_G1);
    NoiseModel out = model;
    std::vector<MeasuredNoiseLine>& lines = out.measuredLines;
    const auto at = std::lower_bound(lines.begin(), lines.end(), measured.gain,
                                     [](const MeasuredNoiseLine& l, double g) { return l.gain < g; });
    if (at != lines.end() && at->gain == measured.gain)
        *at = measured;
    else
        lines.insert(at, measured);
    out.validate();
    return out;
}

namespace {

//! How far values that one exact model produced may disagree after a round trip through 17-digit text.
const double kExactRelative = 1e-9;

bool agrees(double a, double b)
{
    return std::abs(a - b) <= kExactRelative * std::max(std::abs(a), std::abs(b));
}

void checkBaseIso(double baseIso, const char* who)
{
    detail::checkBaseIso(baseIso, (String(who) + ": baseIso").c_str(), false);
}

void checkHaarVarianceRatio(double c, const char* who)
{
    if (!(c > 0 && c <= 1))
        CV_Error(Error::StsBadArg, format("%s: haarVarianceRatio = %g must lie in (0, 1]", who, c));
}

String jsonString(const String& text)
{
    String out = "\"";
    for (char c : text) {
        if (c == '"' || c == '\\')
            out += '\\';
        if (static_cast<unsigned char>(c) < 0x20)
            out += format("\\u%04x", int(c));
        else
            out += c;
    }
    return out + "\"";
}

String jsonNumber(double v)
{
    return format("%.17g", v);
}

} // namespace

namespace {

/** Neither darktable's nor Android's format has a place for the failed_calibration mark: an export
 * would turn a model that NoiseModel::load() refuses into one every reader takes. */
void refuseFailedCalibrationExport(const NoiseModel& model, const char* who)
{
    if (!model.failedCalibration.empty())
        CV_Error(Error::StsBadArg,
                 cv::format("%s: the model is marked failed_calibration (%s); the exported profile could not "
                            "carry the mark, so it is not exported",
                            who, model.failedCalibration.c_str()));
}

} // namespace

String darktableNoiseProfiles(const NoiseModel& model, const RawFormat& format, double baseIso,
                              const std::vector<double>& isos, const String& maker, const String& cameraModel,
                              double haarVarianceRatio)
{
    const char* who = "darktableNoiseProfiles";
    checkBaseIso(baseIso, who);
    checkHaarVarianceRatio(haarVarianceRatio, who);
    refuseFailedCalibrationExport(model, who);
    const double c = haarVarianceRatio;
    if (isos.empty())
        CV_Error(Error::StsBadArg, "darktableNoiseProfiles: no ISO given");
    if (maker.empty() || cameraModel.empty())
        CV_Error(Error::StsBadArg,
                 "darktableNoiseProfiles: the maker and the camera model must not be empty");
    std::vector<double> sorted = isos;
    std::sort(sorted.begin(), sorted.end());
    for (size_t k = 0; k < sorted.size(); ++k) {
        if (!(std::isfinite(sorted[k]) && sorted[k] > 0))
            CV_Error(Error::StsBadArg, cv::format("%s: ISO %g must be finite and > 0", who, sorted[k]));
        if (k > 0 && sorted[k] == sorted[k - 1])
            CV_Error(Error::StsBadArg, cv::format("%s: ISO %g is given twice", who, sorted[k]));
    }
    std::ostringstream out;
    out << "{\n  \"version\": 0,\n  \"noiseprofiles\": [\n    {\n      \"maker\": " << jsonString(maker)
        << ",\n      \"models\": [\n        {\n          \"model\": " << jsonString(cameraModel)
        << ",\n          \"comment\": \"cv::rawgment: alpha " << jsonNumber(model.alpha) << ", sigma_d^2 "
        << jsonNumber(model.sigmaD2) << ", sigma_r^2 " << jsonNumber(model.sigmaR2) << " at base ISO "
        << jsonNumber(baseIso) << ", in darktable's units (Haar variance ratio " << jsonNumber(c)
        << ")\",\n          \"profiles\": [\n";
    for (size_t k = 0; k < sorted.size(); ++k) {
        RawFormat atIso = format;
        atIso.gain = sorted[k] / baseIso;
        const std::vector<Vec2d> so = dngNoiseProfile(model, atIso);
        out << "            {\"name\": " << jsonString(cameraModel + cv::format(" iso %g", sorted[k]))
            << ", \"iso\": " << jsonNumber(sorted[k]) << ",\n             \"a\": ["
            << jsonNumber(c * so[0][0]) << ", " << jsonNumber(c * so[1][0]) << ", "
            << jsonNumber(c * so[2][0]) << "],\n             \"b\": [" << jsonNumber(c * so[0][1]) << ", "
            << jsonNumber(c * so[1][1]) << ", " << jsonNumber(c * so[2][1]) << "]}"
            << (k + 1 < sorted.size() ? ",\n" : "\n");
    }
    out << "          ]\n        }\n      ]\n    }\n  ]\n}\n";
    return out.str();
}

namespace {

//! One ISO's profile as darktable states it: a and b per colour plane.
struct ExportedProfile
{
    double iso;
    std::vector<double> a, b;
};

//! Every profile of one camera in a darktable noise-profile file, read strictly (unknown keys refused).
std::vector<ExportedProfile> readExportedProfiles(const String& path, const String& where,
                                                  const String& maker, const String& cameraModel)
{
    FileStorage fs = openFileStorageForReading(path, "darktable noise profiles");
    std::vector<ExportedProfile> profiles;
    std::vector<String> entries;
    try {
        const FileNode root = fs.root();
        rejectUnknownKeys(root, {"version", "noiseprofiles"});
        if (!root["noiseprofiles"].isSeq())
            CV_Error(Error::StsParseError, "expected a list 'noiseprofiles'");
        for (const FileNode& makerNode : root["noiseprofiles"]) {
            rejectUnknownKeys(makerNode, {"maker", "models", "comment"});
            if (!makerNode["maker"].isString() || !makerNode["models"].isSeq())
                CV_Error(Error::StsParseError, "a maker entry needs a string 'maker' and a list 'models'");
            for (const FileNode& modelNode : makerNode["models"]) {
                rejectUnknownKeys(modelNode, {"model", "comment", "profiles"});
                if (!modelNode["model"].isString() || !modelNode["profiles"].isSeq())
                    CV_Error(Error::StsParseError,
                             "a model entry needs a string 'model' and a list 'profiles'");
                entries.push_back(String(makerNode["maker"]) + " / " + String(modelNode["model"]));
                if (String(makerNode["maker"]) != maker || String(modelNode["model"]) != cameraModel)
                    continue;
                for (const FileNode& p : modelNode["profiles"]) {
                    rejectUnknownKeys(p, {"name", "iso", "a", "b", "skip", "comment"});
                    if (detail::readOptionalFlagField(p, "skip", false))
                        continue;
                    ExportedProfile profile{detail::readRealField(p, "iso"), detail::readRealList(p, "a", 3),
                                            detail::readRealList(p, "b", 3)};
                    if (!(std::isfinite(profile.iso) && profile.iso > 0))
                        CV_Error(Error::StsParseError,
                                 cv::format("ISO %g must be finite and > 0", profile.iso));
                    profiles.push_back(profile);
                }
            }
        }
    } catch (const Exception& e) {
        CV_Error(Error::StsParseError, where + ": " + e.err);
    }
    if (profiles.empty()) {
        String known;
        for (const String& e : entries)
            known += (known.empty() ? "" : ", ") + e;
        CV_Error(Error::StsParseError, where + " has no profile of '" + maker + " / " + cameraModel +
                                           "' (it has: " + (known.empty() ? String("none") : known) + ")");
    }

    return profiles;
}

} // namespace

namespace {

// A calibrated model carries its per-gain fits as measured lines, which its export writes ISO by ISO: no one
// Eq. 5 model gives them back, but the catalogue reads each ISO's line.
const char* const kLinesReader = " (an export of a model with measured lines, such as a calibration's, holds "
                                 "one line per ISO: read it with "
                                 "readCameraProfiles() and CameraNoiseProfile::modelFor(), or "
                                 "loadAnyNoiseModel(), which keep each ISO's line)";

} // namespace

NoiseModel noiseModelFromDarktableExport(const String& path, const RawFormat& format, double baseIso,
                                         const String& maker, const String& cameraModel,
                                         double haarVarianceRatio)
{
    checkBaseIso(baseIso, "noiseModelFromDarktableExport");
    checkHaarVarianceRatio(haarVarianceRatio, "noiseModelFromDarktableExport");
    const double c = haarVarianceRatio;
    format.validate();
    const String where = "noiseModelFromDarktableExport: '" + path + "'";
    const std::vector<ExportedProfile> profiles = readExportedProfiles(path, where, maker, cameraModel);

    // alpha from every colour and ISO; sigma_d^2 and sigma_r^2 from b r^2 = g^2 sigma_d^2 + sigma_r^2.
    double alpha = 0;
    bool haveAlpha = false;
    std::vector<double> x, y;
    std::set<double> distinct;
    for (const ExportedProfile& p : profiles) {
        const double g = p.iso / baseIso;
        distinct.insert(g);
        for (int plane = 0; plane < 3; ++plane) {
            const double r = detail::rangeOfColourPlane(format, plane);
            if (!(std::isfinite(p.a[size_t(plane)]) && p.a[size_t(plane)] >= 0 &&
                  std::isfinite(p.b[size_t(plane)])))
                CV_Error(Error::StsBadArg,
                         cv::format("%s: ISO %g colour %d has a = %g, b = %g; a must be "
                                    "finite and >= 0, b finite",
                                    where.c_str(), p.iso, plane, p.a[size_t(plane)], p.b[size_t(plane)]));
            const double a = p.a[size_t(plane)] * r / (c * g);
            if (!haveAlpha) {
                alpha = a;
                haveAlpha = true;
            } else if (!agrees(a, alpha))
                CV_Error(
                    Error::StsBadArg,
                    cv::format("%s: ISO %g colour %d gives alpha %.9g where another gives %.9g; the model "
                               "has one alpha for every colour and ISO, so this profile has no exact "
                               "counterpart%s",
                               where.c_str(), p.iso, plane, a, alpha, kLinesReader));
            x.push_back(g * g);
            y.push_back(p.b[size_t(plane)] * r * r / c);
        }
    }
    if (distinct.size() < 2)
        CV_Error(Error::StsBadArg, where + ": profiles at one ISO only; sigma_d^2 and sigma_r^2 need two");
    double mx = 0, my = 0;
    for (size_t k = 0; k < x.size(); ++k) {
        mx += x[k] / double(x.size());
        my += y[k] / double(y.size());
    }
    double sxx = 0, sxy = 0;
    for (size_t k = 0; k < x.size(); ++k) {
        sxx += (x[k] - mx) * (x[k] - mx);
        sxy += (x[k] - mx) * (y[k] - my);
    }
    NoiseModel model;
    model.alpha = alpha;
    model.sigmaD2 = sxy / sxx;
    model.sigmaR2 = my - model.sigmaD2 * mx;
    const double scale = *std::max_element(y.begin(), y.end());
    for (size_t k = 0; k < x.size(); ++k)
        if (std::abs(model.sigmaD2 * x[k] + model.sigmaR2 - y[k]) > kExactRelative * scale)
            CV_Error(Error::StsBadArg,
                     cv::format(
                         "%s: the offsets b r^2 are not on one line in g^2 (%.9g at g^2 = %g where the line "
                         "gives %.9g); the model has no exact counterpart%s",
                         where.c_str(), y[k], x[k], model.sigmaD2 * x[k] + model.sigmaR2, kLinesReader));
    // Rounding can leave a term that is exactly zero a hair below it.
    if (std::abs(model.sigmaD2) <= kExactRelative * scale)
        model.sigmaD2 = std::max(model.sigmaD2, 0.0);
    if (std::abs(model.sigmaR2) <= kExactRelative * scale)
        model.sigmaR2 = std::max(model.sigmaR2, 0.0);
    try {
        model.validate();
    } catch (const Exception& e) {
        CV_Error(Error::StsBadArg, where + ": the profiles give an invalid model: " + e.err);
    }
    model.baseIso = baseIso;
    return model;
}

AndroidNoiseProfile androidNoiseProfile(const NoiseModel& model, const RawFormat& format, double baseIso)
{
    checkBaseIso(baseIso, "androidNoiseProfile");
    model.validate();
    refuseFailedCalibrationExport(model, "androidNoiseProfile");
    format.validate();
    AndroidNoiseProfile p;
    for (int site = 0; site < 4; ++site) {
        const double r = format.whiteLevel - format.blackLevel[site];
        p.A[site] = model.alpha / (r * baseIso);
        p.B[site] = 0;
        p.C[site] = model.sigmaD2 / (r * baseIso * r * baseIso);
        p.D[site] = model.sigmaR2 / (r * r);
    }
    return p;
}

NoiseModel noiseModelFromAndroid(const AndroidNoiseProfile& profile, const RawFormat& format, double baseIso)
{
    checkBaseIso(baseIso, "noiseModelFromAndroid");
    format.validate();
    NoiseModel model;
    for (int site = 0; site < 4; ++site) {
        const double r = format.whiteLevel - format.blackLevel[site];
        const double values[4] = {profile.A[site], profile.B[site], profile.C[site], profile.D[site]};
        for (double v : values)
            if (!std::isfinite(v))
                CV_Error(Error::StsBadArg,
                         cv::format("noiseModelFromAndroid: site %d has a non-finite value", site));
        if (profile.B[site] != 0)
            CV_Error(Error::StsBadArg,
                     cv::format(
                         "noiseModelFromAndroid: site %d has B = %g; the model's shot noise is proportional "
                         "to the gain (B = 0), so this profile has no exact counterpart",
                         site, profile.B[site]));
        const NoiseModel here(profile.A[site] * r * baseIso, profile.C[site] * (r * baseIso) * (r * baseIso),
                              profile.D[site] * r * r);
        if (site == 0) {
            model = here;
            continue;
        }
        const double got[3] = {here.alpha, here.sigmaD2, here.sigmaR2};
        const double first[3] = {model.alpha, model.sigmaD2, model.sigmaR2};
        const char* names[3] = {"alpha", "sigma_d^2", "sigma_r^2"};
        for (int k = 0; k < 3; ++k)
            if (!agrees(got[k], first[k]))
                CV_Error(
                    Error::StsBadArg,
                    cv::format("noiseModelFromAndroid: site %d gives %s %.9g where site 0 gives %.9g; the "
                               "model has one set of parameters for every colour, so this profile has no "
                               "exact counterpart",
                               site, names[k], got[k], first[k]));
    }
    try {
        model.validate();
    } catch (const Exception& e) {
        CV_Error(Error::StsBadArg, "noiseModelFromAndroid: the profile gives an invalid model: " + e.err);
    }
    model.baseIso = baseIso;
    return model;
}

} // namespace rawgment
} // namespace cv
