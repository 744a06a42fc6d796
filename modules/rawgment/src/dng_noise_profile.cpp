// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The DNG NoiseProfile tag (51041): from and to a NoiseModel, and read from a DNG's IFDs, which
// LibRaw 0.20 parses but does not expose (raw_io topic).
#include "precomp.hpp"

#include <opencv2/rawgment/raw_io.hpp>

#include <cstring>
#include <fstream>
#include <set>
#include <vector>

namespace cv {
namespace rawgment {

namespace {

//! DNG colour plane (CFAPlaneColor 0, 1, 2) of a CFA site.
int colourPlaneOf(CfaChannel channel)
{
    return channel == CFA_R ? 0 : (channel == CFA_B ? 2 : 1);
}

//! White level minus the mean black level of the sites of one colour plane.
double rangeOfColourPlane(const RawFormat& format, int plane)
{
    double black = 0;
    int sites = 0;
    for (int site = 0; site < 4; ++site)
        if (colourPlaneOf(cfaChannelAt(format.pattern, site / 2, site % 2)) == plane) {
            black += format.blackLevel[site];
            ++sites;
        }
    return format.whiteLevel - black / sites;
}

//! Bounded reads of a TIFF file of either byte order: every offset is checked against the file's size,
//! so a hostile file gives an error naming it, never a read outside it.
class TiffFile
{
public:
    explicit TiffFile(const String& path) : path_(path), in_(path, std::ios::binary)
    {
        if (!in_)
            fail("cannot be opened");
        in_.seekg(0, std::ios::end);
        size_ = static_cast<uint64_t>(in_.tellg());
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
    uint16_t u16(uint64_t at)
    {
        unsigned char b[2];
        bytes(at, b, 2);
        return bigEndian_ ? uint16_t(b[0] << 8 | b[1]) : uint16_t(b[1] << 8 | b[0]);
    }
    uint32_t u32(uint64_t at)
    {
        unsigned char b[4];
        bytes(at, b, 4);
        uint32_t v = 0;
        for (int k = 0; k < 4; ++k)
            v |= uint32_t(b[bigEndian_ ? k : 3 - k]) << (8 * (3 - k));
        return v;
    }
    double f64(uint64_t at)
    {
        unsigned char b[8];
        bytes(at, b, 8);
        uint64_t v = 0;
        for (int k = 0; k < 8; ++k)
            v |= uint64_t(b[bigEndian_ ? k : 7 - k]) << (8 * (7 - k));
        double d;
        std::memcpy(&d, &v, sizeof(d));
        return d;
    }
    [[noreturn]] void fail(const String& why) const
    {
        CV_Error(Error::StsParseError, "readRaw: '" + path_ + "' " + why);
    }

private:
    void bytes(uint64_t at, void* out, uint64_t n)
    {
        if (at > size_ || n > size_ - at)
            fail(format("is truncated: a TIFF field at byte %llu lies beyond its end (%llu bytes)",
                        static_cast<unsigned long long>(at), static_cast<unsigned long long>(size_)));
        in_.seekg(static_cast<std::streamoff>(at));
        in_.read(static_cast<char*>(out), static_cast<std::streamsize>(n));
        if (!in_)
            fail("could not be read");
    }
    String path_;
    std::ifstream in_;
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

//! The NoiseProfile pairs of a TIFF-based file (DNG), empty when it has none or is not TIFF-based.
std::vector<Vec2d> readDngNoiseProfile(const String& path)
{
    {
        std::ifstream probe(path, std::ios::binary);
        char head[4] = {0, 0, 0, 0};
        probe.read(head, 4);
        const bool tiff = probe && ((head[0] == 'I' && head[1] == 'I' && head[2] == 42 && head[3] == 0) ||
                                    (head[0] == 'M' && head[1] == 'M' && head[2] == 0 && head[3] == 42));
        if (!tiff)
            return {};
    }
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

std::vector<Vec2d> dngNoiseProfile(const NoiseModel& model, const RawFormat& format)
{
    format.validate();
    model.validate();
    const double g = format.gain;
    std::vector<Vec2d> profile(3);
    for (int plane = 0; plane < 3; ++plane) {
        const double r = rangeOfColourPlane(format, plane);
        profile[plane] = Vec2d(g * model.alpha / r, (g * g * model.sigmaD2 + model.sigmaR2) / (r * r));
    }
    detail::checkDngNoiseProfile(profile, "dngNoiseProfile");
    return profile;
}

NoiseLine noiseLineFromDngProfile(const std::vector<Vec2d>& profile, const RawFormat& format,
                                  CfaChannel channel)
{
    detail::checkDngNoiseProfile(profile, "noiseLineFromDngProfile");
    format.validate();
    const int plane = colourPlaneOf(channel);
    const Vec2d so = profile.size() == 1 ? profile[0] : profile[static_cast<size_t>(plane)];
    const double r = rangeOfColourPlane(format, plane);
    NoiseLine line;
    line.a = so[0] * r;
    line.b = so[1] * r * r;
    return line;
}

} // namespace rawgment
} // namespace cv
