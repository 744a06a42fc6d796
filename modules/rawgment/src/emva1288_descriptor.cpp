// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The EMVA 1288 descriptor and its images (emva1288 topic). The descriptor is read as the standard's
// reference implementation reads it (commands v, n, b, d, i; '#' comments; CRLF; Windows separators; a
// decimal comma), but strictly: what it would warn about and skip is an error naming the line here. An
// image's header is read before the image is decoded, so a file that claims a huge image allocates nothing.
#include "image_headers.hpp"
#include "precomp.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/rawgment/emva1288.hpp>

#include <cstdlib>
#include <map>
#include <sstream>
#include <tuple>

namespace cv {
namespace rawgment {

namespace {

//! A descriptor of the largest series the caps allow is a few MB; anything longer is not one.
constexpr long long kMaxDescriptorBytes = 16LL << 20;

[[noreturn]] void badLine(const String& path, int line, const std::string& why)
{
    CV_Error(Error::StsParseError,
             cv::format("EMVA 1288 descriptor '%s', line %d: %s", path.c_str(), line, why.c_str()));
}

std::vector<std::string> wordsOf(const std::string& line)
{
    std::vector<std::string> words;
    std::istringstream in(line);
    for (std::string w; in >> w;)
        words.push_back(w);
    return words;
}

//! A finite real in the descriptor's spelling (a decimal comma is read as a point, as the reference does).
double realOf(const String& path, int line, std::string word, const char* what)
{
    for (char& c : word)
        if (c == ',')
            c = '.';
    // Decimal only: strtod also takes hex (0x3e8) and "inf", which the reference's float() reads otherwise
    // or not at all (decided for #79's minor items).
    if (word.find_first_not_of("0123456789+-.eE") != std::string::npos)
        badLine(path, line, cv::format("%s '%s' is not a decimal number", what, word.c_str()));
    const char* begin = word.c_str();
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(begin, &end);
    if (end == begin || *end != '\0' || errno == ERANGE || !std::isfinite(v))
        badLine(path, line, cv::format("%s '%s' is not a finite number", what, word.c_str()));
    return v;
}

long long integerOf(const String& path, int line, const std::string& word, const char* what)
{
    const char* begin = word.c_str();
    char* end = nullptr;
    errno = 0;
    const long long v = std::strtoll(begin, &end, 10);
    if (end == begin || *end != '\0' || errno == ERANGE)
        badLine(path, line, cv::format("%s '%s' is not an integer", what, word.c_str()));
    return v;
}

//! An `i` line's path, Windows separators as '/', resolved against the descriptor's folder.
String resolvedImagePath(const String& folder, std::string name)
{
    for (char& c : name)
        if (c == '\\')
            c = '/';
    return (!name.empty() && name[0] == '/') ? String(name) : folder + name;
}

} // namespace

namespace {

//! The text with its line ends CRLF, LF or a lone CR (classic Mac OS) as LF: with CR alone, every line was
//! "line 1".
std::string withUnixLineEnds(const std::string& text)
{
    std::string unified;
    unified.reserve(text.size());
    for (size_t k = 0; k < text.size(); ++k)
        if (text[k] != '\r')
            unified += text[k];
        else if (k + 1 == text.size() || text[k + 1] != '\n')
            unified += '\n';
    return unified;
}

//! A descriptor read line by line: each command's line checked where it stands, naming it.
class DescriptorReader
{
public:
    DescriptorReader(const String& path, Emva1288Series& series)
        : path_(path), folder_(detail::folderOf(path)), series_(series)
    {
    }

    void line(const std::string& raw, int lineNumber)
    {
        const std::vector<std::string> words = wordsOf(raw);
        if (words.empty() || words[0][0] == '#')
            return;
        const std::string& command = words[0];
        if (command == "i") {
            imageLine(raw, words, lineNumber);
            return;
        }
        closeExposure();
        if (command == "v")
            versionLine(words, lineNumber);
        else if (command == "n")
            formatLine(words, lineNumber);
        else if (command == "b" || command == "d")
            exposureLine(words, lineNumber);
        else
            badLine(path_, lineNumber,
                    "unknown command '" + command +
                        "' (a descriptor has 'v', 'n', 'b', 'd', 'i' and '#' comment lines): is it an EMVA "
                        "1288 descriptor?");
    }

    //! After the last line: the exposures, each with its images.
    std::vector<Emva1288Images> exposures()
    {
        closeExposure();
        if (!sawFormat_)
            CV_Error(Error::StsParseError,
                     "EMVA 1288 descriptor '" + path_ +
                         "' is not a descriptor: it has no 'n <bits> <width> <height>' line");
        return groups_;
    }

private:
    void closeExposure()
    {
        if (open_ && open_->images.size() < 2)
            badLine(path_, open_->line,
                    cv::format("the exposure has %d image(s); every step needs at least two",
                               int(open_->images.size())));
        open_ = nullptr;
    }

    void imageLine(const std::string& raw, const std::vector<std::string>& words, int lineNumber)
    {
        if (!open_)
            badLine(path_, lineNumber, "an image ('i') before any 'b' or 'd' line");
        if (words.size() < 2)
            badLine(path_, lineNumber, "expected 'i <image path>'");
        // A path may hold spaces: the rest of the line after the command is the path.
        const size_t start = raw.find_first_not_of(" \t", raw.find('i') + 1);
        std::string name = raw.substr(start);
        name.erase(name.find_last_not_of(" \t") + 1);
        if (++imageCount_ > MAX_EMVA1288_IMAGES)
            badLine(path_, lineNumber,
                    cv::format("more than %d images; a descriptor may list at most that many",
                               MAX_EMVA1288_IMAGES));
        const String image = resolvedImagePath(folder_, name);
        if (!pathExists(image))
            badLine(path_, lineNumber, "image '" + image + "' does not exist");
        detail::checkRegularFile(image, "EMVA 1288 image (descriptor '" + path_ +
                                            cv::format("', line %d)", lineNumber));
        // Each image by its file's identity: one image listed twice (in a pair, a stack or two steps) made a
        // temporal variance of 0 between them, and every figure carried it.
        detail::FileIdentity id;
        if (detail::fileIdentityOf(image, id)) {
            const auto first = imageLines_.emplace(id, std::make_pair(lineNumber, image));
            if (!first.second)
                badLine(path_, lineNumber,
                        cv::format("image '%s' is the file of line %d ('%s'); every image of a series is "
                                   "a capture of its own",
                                   image.c_str(), first.first->second.first,
                                   first.first->second.second.c_str()));
        }
        open_->images.push_back(image);
    }

    void versionLine(const std::vector<std::string>& words, int lineNumber)
    {
        if (words.size() != 2)
            badLine(path_, lineNumber, "expected 'v <release>'");
        if (versionLine_ > 0)
            badLine(path_, lineNumber,
                    cv::format("a second 'v' line (the first is line %d): which release holds is a guess",
                               versionLine_));
        versionLine_ = lineNumber;
        series_.version = words[1];
    }

    void formatLine(const std::vector<std::string>& words, int lineNumber)
    {
        if (words.size() != 4)
            badLine(path_, lineNumber, "expected 'n <bits> <width> <height>'");
        if (sawFormat_)
            badLine(path_, lineNumber, "a second 'n' line; a descriptor has one");
        const long long bits = integerOf(path_, lineNumber, words[1], "bits");
        const long long width = integerOf(path_, lineNumber, words[2], "width");
        const long long height = integerOf(path_, lineNumber, words[3], "height");
        if (bits < 1 || bits > MAX_EMVA1288_BITS)
            badLine(path_, lineNumber, cv::format("bits %lld is outside [1, %d]", bits, MAX_EMVA1288_BITS));
        if (width < 1 || height < 1)
            badLine(path_, lineNumber, cv::format("the size %lld x %lld is empty", width, height));
        if (width > MAX_EMVA1288_PIXELS || height > MAX_EMVA1288_PIXELS ||
            width * height > MAX_EMVA1288_PIXELS)
            badLine(path_, lineNumber,
                    cv::format("%lld x %lld pixels is more than the %lld pixels an image may have", width,
                               height, MAX_EMVA1288_PIXELS));
        series_.bits = int(bits);
        series_.width = int(width);
        series_.height = int(height);
        sawFormat_ = true;
    }

    void exposureLine(const std::vector<std::string>& words, int lineNumber)
    {
        const bool dark = words[0] == "d";
        if (!sawFormat_)
            badLine(path_, lineNumber, "an exposure before the 'n <bits> <width> <height>' line");
        if (words.size() != (dark ? 2u : 3u))
            badLine(path_, lineNumber,
                    dark ? "expected 'd <exposure>'" : "expected 'b <exposure> <photons>'");
        Emva1288Images group;
        group.dark = dark;
        group.line = lineNumber;
        group.exposureNs = realOf(path_, lineNumber, words[1], "exposure");
        group.photons = dark ? 0.0 : realOf(path_, lineNumber, words[2], "photons");
        if (group.exposureNs < 0)
            badLine(path_, lineNumber, cv::format("exposure %g is negative", group.exposureNs));
        if (group.photons < 0)
            badLine(path_, lineNumber, cv::format("photons %g is negative", group.photons));
        if (group.exposureNs > MAX_EMVA1288_EXPOSURE)
            badLine(path_, lineNumber,
                    cv::format("exposure %g is beyond the %g a descriptor may state", group.exposureNs,
                               MAX_EMVA1288_EXPOSURE));
        if (group.photons > MAX_EMVA1288_PHOTONS)
            badLine(path_, lineNumber,
                    cv::format("photons %g is beyond the %g a descriptor may state", group.photons,
                               MAX_EMVA1288_PHOTONS));
        groups_.push_back(group);
        open_ = &groups_.back();
    }

    String path_, folder_;
    Emva1288Series& series_;
    std::vector<Emva1288Images> groups_;
    Emva1288Images* open_ = nullptr;
    bool sawFormat_ = false;
    long long imageCount_ = 0;
    int versionLine_ = 0;
    std::map<detail::FileIdentity, std::pair<int, String>> imageLines_;
};

/* The exposures sorted into temporal (pairs) and spatial (stacks) as the reference classifies them; a (kind,
 * exposure, photons) once, every temporal exposure with a dark and a bright pair, the spatial set one bright
 * and one dark stack. */
void classifyExposures(const String& path, const std::vector<Emva1288Images>& groups, Emva1288Series& series)
{
    std::map<std::tuple<bool, double, double>, int> seen[2];
    for (const Emva1288Images& g : groups) {
        const bool temporal = g.images.size() == 2;
        const int previous =
            seen[temporal].emplace(std::make_tuple(g.dark, g.exposureNs, g.photons), g.line).first->second;
        if (previous != g.line)
            badLine(path, g.line,
                    cv::format("exposure %g with %s is listed again (first on line %d)", g.exposureNs,
                               g.dark ? "no light" : cv::format("%g photons", g.photons).c_str(), previous));
        (temporal ? series.temporal : series.spatial).push_back(g);
    }
    for (const Emva1288Images& g : series.temporal) {
        bool dark = false, bright = false;
        for (const Emva1288Images& o : series.temporal)
            if (o.exposureNs == g.exposureNs)
                (o.dark ? dark : bright) = true;
        if (!dark || !bright)
            badLine(path, g.line,
                    cv::format("exposure %g has %s; every temporal exposure needs a dark pair ('d') and a "
                               "bright pair ('b')",
                               g.exposureNs, dark ? "no bright pair" : "no dark pair"));
    }
    if (!series.spatial.empty()) {
        const bool onePair = series.spatial.size() == 2 && series.spatial[0].dark != series.spatial[1].dark &&
                             series.spatial[0].exposureNs == series.spatial[1].exposureNs;
        if (!onePair)
            badLine(
                path, series.spatial[0].line,
                "the spatial set (exposures of more than two images) must be one bright and one dark stack "
                "at one exposure time");
    }
}

} // namespace

Emva1288Series readEmva1288(const String& path)
{
    const std::string text = readFileBounded(path, kMaxDescriptorBytes, "EMVA 1288 descriptor");
    if (text.find('\0') != std::string::npos)
        CV_Error(Error::StsParseError,
                 "EMVA 1288 descriptor '" + path + "' is not a descriptor: it holds binary data");
    Emva1288Series series;
    series.path = path;
    DescriptorReader reader(path, series);
    std::istringstream lines(withUnixLineEnds(text));
    int lineNumber = 0;
    for (std::string raw; std::getline(lines, raw);)
        reader.line(raw, ++lineNumber);
    classifyExposures(path, reader.exposures(), series);
    return series;
}

Mat readEmva1288Image(const Emva1288Series& series, const String& imagePath, int line)
{
    const String where = cv::format("EMVA 1288 image '%s' (descriptor '%s', line %d)", imagePath.c_str(),
                                    series.path.c_str(), line);
    const auto fail = [&](const std::string& why) { CV_Error(Error::StsError, where + ": " + why); };
    if (series.width < 1 || series.height < 1 || series.bits < 1 || series.bits > MAX_EMVA1288_BITS ||
        (long long)series.width * series.height > MAX_EMVA1288_PIXELS)
        CV_Error(Error::StsBadArg,
                 "readEmva1288Image: the series' 'n' is invalid; read it with readEmva1288()");
    // A PNG may be a little larger than its pixels (incompressible noise); 16 bits each, twice, bounds both.
    const long long maxBytes = 4LL * series.width * series.height + (1LL << 20);
    const std::string bytes = readFileBounded(imagePath, maxBytes, where);
    detail::ImageHeader h;
    std::string why;
    if (!detail::readImageHeader(bytes, h, why))
        fail(why.empty() ? "it is neither a PNG nor a TIFF image" : why);
    if (h.width != series.width || h.height != series.height)
        fail(cv::format("it is %lld x %lld, but the descriptor's 'n' line says %d x %d", h.width, h.height,
                        series.width, series.height));
    if (h.channels != 1 || (h.bitDepth != 8 && h.bitDepth != 16))
        fail(cv::format("it has %d channel(s) of %d bits; the standard's images are one channel in an 8- or "
                        "16-bit container",
                        h.channels, h.bitDepth));
    Mat image;
    try {
        image = imdecode(Mat(1, int(bytes.size()), CV_8U, const_cast<char*>(bytes.data())), IMREAD_UNCHANGED);
    } catch (const Exception& e) {
        fail(std::string("it cannot be decoded: ") + e.what());
    }
    if (image.empty())
        fail("it cannot be decoded");
    if (image.size() != Size(series.width, series.height) ||
        (image.type() != CV_8UC1 && image.type() != CV_16UC1))
        fail(cv::format("it decodes as %dx%d %s; the header said %lld x %lld, one channel of %d bits",
                        image.cols, image.rows, typeToString(image.type()).c_str(), h.width, h.height,
                        h.bitDepth));
    double maxValue = 0;
    Point at;
    minMaxLoc(image, nullptr, &maxValue, nullptr, &at);
    const double limit = std::ldexp(1.0, series.bits) - 1;
    if (maxValue > limit)
        fail(cv::format("pixel (x %d, y %d) is %g, above 2^%d - 1 = %g that the descriptor's bits allow",
                        at.x, at.y, maxValue, series.bits, limit));
    return image;
}

} // namespace rawgment
} // namespace cv
