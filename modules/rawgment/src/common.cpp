// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "precomp.hpp"

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstring>
#include <fstream>
#include <iterator>
#include <regex>
#include <sstream>
#include <unistd.h>

namespace cv {
namespace rawgment {
namespace detail {

void checkFinitePositive(double value, const char* what)
{
    if (!std::isfinite(value) || value <= 0)
        CV_Error(Error::StsBadArg, format("%s must be finite and > 0 (got %g)", what, value));
}

void checkFiniteNonNegative(double value, const char* what)
{
    if (!std::isfinite(value) || value < 0)
        CV_Error(Error::StsBadArg, format("%s must be finite and >= 0 (got %g)", what, value));
}

Mat normalisedKernel(InputArray _kernel, const char* who)
{
    Mat kernel;
    _kernel.getMat().convertTo(kernel, CV_64F);
    if (kernel.empty() || !checkRange(kernel, true))
        CV_Error(Error::StsBadArg, format("%s: kernel must be non-empty and finite", who));
    double lo = 0;
    minMaxLoc(kernel, &lo);
    const double total = sum(kernel)[0];
    if (lo < 0 || !(total > 0))
        CV_Error(Error::StsBadArg, format("%s: kernel must be non-negative with a positive sum", who));
    return kernel / total;
}

namespace {

bool isAbsent(const FileNode& f)
{
    return f.empty() || f.isNone();
}

double numberOf(const FileNode& f, const String& name)
{
    if (!f.isReal() && !f.isInt())
        CV_Error(Error::StsParseError, format("field '%s' is not a number", name.c_str()));
    return static_cast<double>(f);
}

} // namespace

double readRealField(const FileNode& node, const char* field)
{
    const FileNode f = node[field];
    if (isAbsent(f))
        CV_Error(Error::StsParseError, format("field '%s' is missing", field));
    return numberOf(f, field);
}

double readOptionalRealField(const FileNode& node, const char* field, double fallback)
{
    const FileNode f = node[field];
    return isAbsent(f) ? fallback : numberOf(f, field);
}

int readOptionalIntField(const FileNode& node, const char* field, int fallback)
{
    const FileNode f = node[field];
    if (isAbsent(f))
        return fallback;
    const double value = f.isInt() || f.isReal() ? static_cast<double>(f) : 0.5;
    if (value != std::floor(value) || value < INT_MIN || value > INT_MAX)
        CV_Error(Error::StsParseError, format("field '%s' must be an integer", field));
    return static_cast<int>(value);
}

void rejectUnknownKeys(const FileNode& map, const std::vector<const char*>& valid)
{
    if (!map.isMap())
        return;
    for (const FileNode& entry : map) {
        const std::string key = entry.name();
        if (std::none_of(valid.begin(), valid.end(), [&](const char* v) { return key == v; })) {
            std::string list;
            for (const char* v : valid)
                list += (list.empty() ? "" : ", ") + std::string(v);
            CV_Error(Error::StsParseError,
                     format("unknown key '%s' (valid keys: %s)", key.c_str(), list.c_str()));
        }
    }
}

std::vector<double> readRealList(const FileNode& node, const char* field, int n)
{
    const FileNode list = node[field];
    if (!list.isSeq() || static_cast<int>(list.size()) != n)
        CV_Error(Error::StsParseError, format("field '%s' must be a list of %d numbers", field, n));
    std::vector<double> values;
    for (int i = 0; i < n; ++i)
        values.push_back(numberOf(list[i], format("%s[%d]", field, i)));
    return values;
}

int fileStorageFormatOf(const String& path)
{
    const auto endsWith = [&](const char* ext) {
        const size_t n = std::strlen(ext);
        return path.size() >= n && path.compare(path.size() - n, n, ext) == 0;
    };
    if (endsWith(".yml") || endsWith(".yaml"))
        return FileStorage::FORMAT_YAML;
    if (endsWith(".json"))
        return FileStorage::FORMAT_JSON;
    CV_Error(Error::StsBadArg, "'" + path + "': unsupported extension; expected .yml, .yaml or .json");
}

bool fileExists(const String& path)
{
    return ::access(path.c_str(), F_OK) == 0;
}

void rejectWrappingIntegers(const String& path)
{
    // A plain integer scalar: after a key's colon, a list's bracket or comma, or a block list's dash,
    // and before the end of the line, a comma, a closing bracket or a comment. Quoted text is skipped.
    static const std::regex integer(R"((?:^|[:\[,{]|^\s*-)\s*([-+]?\d+)\s*(?=$|[,\]}#]))");
    std::istringstream lines(readTextFile(path));
    std::string line;
    for (int number = 1; std::getline(lines, line); ++number) {
        std::string unquoted;
        char quote = 0;
        for (char c : line) {
            if (quote) {
                quote = c == quote ? 0 : quote;
                continue;
            }
            if (c == '"' || c == '\'') {
                quote = c;
                continue;
            }
            unquoted += c;
        }
        for (std::sregex_iterator it(unquoted.begin(), unquoted.end(), integer), end; it != end; ++it) {
            const std::string digits = (*it)[1];
            errno = 0;
            const long long value = std::strtoll(digits.c_str(), nullptr, 10);
            if (errno == ERANGE || value > INT_MAX || value < INT_MIN)
                CV_Error(
                    Error::StsParseError,
                    format("'%s' line %d: the integer %s does not fit 32 bits (OpenCV's reader would wrap "
                           "it); write it as a real (%s.0) if that is the value meant",
                           path.c_str(), number, digits.c_str(), digits.c_str()));
        }
    }
}

std::string readTextFile(const String& path)
{
    std::ifstream f(path, std::ios::binary);
    if (!f)
        CV_Error(Error::StsError, "cannot open '" + path + "': " + std::strerror(errno));
    std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    if (f.bad())
        CV_Error(Error::StsError, "cannot read '" + path + "'");
    return text;
}

} // namespace detail
} // namespace rawgment
} // namespace cv
