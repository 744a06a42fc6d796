// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The files topic (files.hpp), its text checks: every YAML/JSON text a reader of this module opens is
// parsed by libyaml (YAML) or nlohmann-json (JSON), in the calling thread and without recursion, its
// scalars typed by YAML 1.2's core schema, and the values written anew by OpenCV's own JSON writer. That
// text is the only one OpenCV's parser is ever given: whatever libyaml and OpenCV 4.6's hand-written
// parser disagree on (numbers it wraps, keys it finds inside plain values, escapes and exponents it does
// not know, streams it loops on) never reaches it. openFileStorageForReading() (files.cpp) calls this.
#include "precomp.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <climits>
#include <cstring>
#include <limits>
#include <map>
#include <type_traits>

#include <nlohmann/json.hpp>
#include <yaml.h>

namespace cv {
namespace rawgment {
namespace detail {
namespace {

// OpenCV 4.6's persistence keeps a string in a buffer of CV_FS_MAX_LEN (4096) bytes with its terminator.
constexpr size_t kMaxStringBytes = 4095;

//! The line (1-based) of byte `offset` of `text`.
int lineAt(const std::string& text, size_t offset)
{
    offset = std::min(offset, text.size());
    return 1 + static_cast<int>(
                   std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(offset), '\n'));
}

//! "'path' line N: why", or "'path': why" where no line is known (line <= 0).
[[noreturn]] void refuseAt(const String& path, int line, const std::string& why)
{
    if (line > 0)
        CV_Error(Error::StsParseError, format("'%s' line %d: %s", path.c_str(), line, why.c_str()));
    CV_Error(Error::StsParseError, format("'%s': %s", path.c_str(), why.c_str()));
}

[[noreturn]] void refuseWrappingInteger(const String& path, int line, const std::string& literal)
{
    const bool decimal = literal.find_first_of("xX") == std::string::npos;
    refuseAt(path, line,
             format("the integer %s does not fit 32 bits (OpenCV's reader would wrap it); write it as a real "
                    "(%s) if that is the value meant",
                    literal.c_str(), decimal ? (literal + ".0").c_str() : "in decimal, with a fraction"));
}

[[noreturn]] void refuseDepth(const String& path, int line)
{
    refuseAt(path, line,
             format("collections nested more than %d levels deep; no file of this module nests so deep "
                    "(OpenCV's recursive reader would overflow the stack)",
                    MAX_NESTING_DEPTH));
}

bool isAsciiDigit(char c)
{
    return c >= '0' && c <= '9';
}

bool isAsciiAlpha(char c)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z');
}

size_t digitsFrom(const std::string& s, size_t at)
{
    size_t n = 0;
    while (at + n < s.size() && isAsciiDigit(s[at + n]))
        ++n;
    return n;
}

/** Writes the values of a parsed text with OpenCV's own JSON writer: the text OpenCV's reader is given.
 * It refuses what that writer cannot write so that its reader reads it back the same (keys outside
 * OpenCV's alphabet, strings it would truncate), repeated keys, nesting beyond
 * MAX_NESTING_DEPTH and integers beyond 32 bits. The root must be a map: it is the storage's own. */
class OpenCvTextWriter
{
public:
    explicit OpenCvTextWriter(const String& path)
        : path_(path), out_(".json", FileStorage::WRITE | FileStorage::MEMORY | FileStorage::FORMAT_JSON)
    {
    }

    bool expectsKey() const { return !levels_.empty() && levels_.back().map && !levels_.back().hasKey; }
    bool empty() const { return !rootSeen_; }

    void startCollection(bool map, int line)
    {
        if (levels_.empty()) {
            if (!map)
                refuseAt(path_, line, "the root is a list, not a map (every file of this module is a map)");
            rootSeen_ = true;
        } else {
            const std::string key = takeKey();
            write(line,
                  [&] { out_.startWriteStruct(key, map ? FileNode::MAP : FileNode::SEQ | FileNode::FLOW); });
        }
        levels_.emplace_back();
        levels_.back().map = map;
        if (static_cast<int>(levels_.size()) > MAX_NESTING_DEPTH)
            refuseDepth(path_, line);
    }

    void endCollection()
    {
        levels_.pop_back();
        if (!levels_.empty())
            out_.endWriteStruct();
    }

    void key(const std::string& name, int line)
    {
        // OpenCV's writer takes these keys only, and its readers find no other reliably.
        const bool valid = !name.empty() && name.size() <= kMaxStringBytes &&
                           (isAsciiAlpha(name[0]) || name[0] == '_') &&
                           std::all_of(name.begin(), name.end(), [](char c) {
                               return isAsciiAlpha(c) || isAsciiDigit(c) || c == '_' || c == '-' || c == ' ';
                           });
        if (!valid)
            refuseAt(path_, line,
                     format("the key '%s' is not one OpenCV's files can hold (a letter or '_', then letters, "
                            "digits, '_', '-' or spaces)",
                            name.substr(0, 80).c_str()));
        Level& level = levels_.back();
        const auto repeated = level.keys.emplace(name, line);
        if (!repeated.second)
            refuseAt(
                path_, line,
                repeated.first->second > 0
                    ? format("key '%s' appears twice (first on line %d); which value counts would be a guess",
                             name.c_str(), repeated.first->second)
                    : format("key '%s' appears twice in one map; which value counts would be a guess",
                             name.c_str()));
        level.key = name;
        level.hasKey = true;
    }

    void integer(long long value, int line, const std::string& literal)
    {
        if (value < INT_MIN || value > INT_MAX)
            refuseWrappingInteger(path_, line, literal);
        const std::string key = takeKey();
        write(line, [&] { out_.write(key, static_cast<int>(value)); });
    }

    //! A boolean as "true"/"false", for the flag reader only: as 1 or 0, `gain_db: true` was 1 dB.
    void boolean(bool value, int line)
    {
        const std::string key = takeKey();
        write(line, [&] { out_.write(key, std::string(value ? "true" : "false")); });
    }

    void real(double value, int line)
    {
        const std::string key = takeKey();
        write(line, [&] { out_.write(key, value); });
    }

    void text(const std::string& value, int line)
    {
        if (value.find('\0') != std::string::npos)
            refuseAt(path_, line, "a NUL character in a string; OpenCV's strings end at a NUL");
        if (value.size() > kMaxStringBytes)
            refuseAt(path_, line,
                     format("a string of %zu bytes; OpenCV's files hold at most %zu", value.size(),
                            kMaxStringBytes));
        // Strings go through writeString() (below); OpenCV's reader takes "$base64$..." for binary data.
        if (value.compare(0, 8, "$base64$") == 0)
            refuseAt(path_, line,
                     "a string that starts with $base64$, which OpenCV's reader takes for binary data");
        const std::string key = takeKey();
        write(line, [&] {
            try {
                writeString(out_, key, value);
            } catch (const Exception&) { // a control character: as OpenCV writes it, for readers that show it
                out_.write(key, value);
            }
        });
    }

    //! A JSON null: a key without a value is left out (a lookup finds nothing, as for a null).
    void null(int line)
    {
        if (!levels_.back().map)
            refuseAt(path_, line, "a null in a list; OpenCV's files have no null");
        takeKey();
    }

    std::string finish() { return out_.releaseAndGetString(); }

private:
    struct Level
    {
        bool map = true;
        bool hasKey = false;
        std::string key;
        std::map<std::string, int> keys;
    };

    std::string takeKey()
    {
        Level& level = levels_.back();
        if (!level.map)
            return std::string();
        level.hasKey = false;
        return level.key;
    }

    template <typename Write> void write(int line, Write&& w)
    {
        try {
            w();
        } catch (const Exception& e) {
            refuseAt(path_, line, "OpenCV's writer refused a value: " + e.err);
        }
    }

    String path_;
    FileStorage out_;
    std::vector<Level> levels_;
    bool rootSeen_ = false;
};

// --------------------------------------------------------------------------------------------------
// YAML: libyaml's events, plain scalars typed by YAML 1.2's core schema.

//! The libyaml parser of one text, freed on every path out.
struct YamlParser
{
    yaml_parser_t parser;
    YamlParser(const char* text, size_t size)
    {
        if (!yaml_parser_initialize(&parser))
            CV_Error(Error::StsNoMem, "cannot initialise the YAML parser");
        yaml_parser_set_input_string(&parser, reinterpret_cast<const unsigned char*>(text), size);
    }
    ~YamlParser() { yaml_parser_delete(&parser); }
    YamlParser(const YamlParser&) = delete;
    YamlParser& operator=(const YamlParser&) = delete;
};

struct YamlEvent
{
    yaml_event_t event;
    bool held = false;
    ~YamlEvent()
    {
        if (held)
            yaml_event_delete(&event);
    }
};

/** Whether OpenCV 4.6's YAML reader takes a plain value for a number: it starts with a digit, a sign
 * before a digit or a dot, or a dot before a letter or digit (persistence_yml.cpp, parseValue). */
bool opencvReadsANumber(const std::string& v)
{
    const char c = v.empty() ? '\0' : v[0], d = v.size() > 1 ? v[1] : '\0';
    return isAsciiDigit(c) || ((c == '-' || c == '+') && (isAsciiDigit(d) || d == '.')) ||
           (c == '.' && (isAsciiDigit(d) || isAsciiAlpha(d)));
}

//! An integer of `digits` in `base`, or false when it does not fit a long long.
bool parseMagnitude(const std::string& digits, int base, long long& value)
{
    const auto result = std::from_chars(digits.data(), digits.data() + digits.size(), value, base);
    return result.ec == std::errc() && result.ptr == digits.data() + digits.size();
}

//! Whether `v` is YAML 1.2's core float: [-+]?(.[0-9]+|[0-9]+(.[0-9]*)?)([eE][-+]?[0-9]+)?
bool isCoreFloat(const std::string& v)
{
    size_t at = v.empty() || (v[0] != '-' && v[0] != '+') ? 0 : 1;
    const size_t whole = digitsFrom(v, at);
    at += whole;
    size_t fraction = 0;
    if (at < v.size() && v[at] == '.') {
        fraction = digitsFrom(v, at + 1);
        at += 1 + fraction;
    }
    if (whole == 0 && fraction == 0)
        return false;
    if (at < v.size() && (v[at] == 'e' || v[at] == 'E')) {
        ++at;
        if (at < v.size() && (v[at] == '-' || v[at] == '+'))
            ++at;
        const size_t exponent = digitsFrom(v, at);
        if (exponent == 0)
            return false;
        at += exponent;
    }
    return at == v.size();
}

class YamlScalarTyper
{
public:
    YamlScalarTyper(const String& path, OpenCvTextWriter& out) : path_(path), out_(out) {}

    //! A plain untagged value, typed by YAML 1.2's core schema; refused where OpenCV's own reader would
    //! have read another type or another value from the same text.
    void plain(const std::string& v, bool inFlow, int line)
    {
        if (v.empty() || v == "~" || v == "null" || v == "Null" || v == "NULL")
            refuse(line,
                   "an empty or null value; OpenCV's files have no null: write a value, or leave the key "
                   "out");
        if (v == "true" || v == "True" || v == "TRUE" || v == "false" || v == "False" || v == "FALSE") {
            out_.boolean(v[0] == 't' || v[0] == 'T', line);
            return;
        }
        if (integer(v, line))
            return;
        if (realNumber(v, line))
            return;
        if (opencvReadsANumber(v))
            refuse(line, format("'%s' is a string to YAML 1.2, but OpenCV's reader takes it for a number: "
                                "quote it if it is text, or write the number as YAML does (1000, 0x1F, "
                                "1.5e-3)",
                                v.substr(0, 80).c_str()));
        if (!inFlow && v.find(':') != std::string::npos)
            refuse(line,
                   format("the plain value '%s' holds ':', which OpenCV's reader takes for a key: quote "
                          "it",
                          v.substr(0, 80).c_str()));
        out_.text(v, line);
    }

    //! A scalar with an explicit tag (!!str, !!int, !!float), read as the tag says.
    void tagged(const std::string& v, const std::string& tag, bool plainStyle, int line)
    {
        static const std::string core = "tag:yaml.org,2002:";
        const std::string name =
            tag.compare(0, core.size(), core) == 0 ? "!!" + tag.substr(core.size()) : tag;
        if (name == "!!str") {
            out_.text(v, line);
        } else if (name == "!!int" && plainStyle) {
            if (!integer(v, line))
                refuse(line, format("'!!int %s' is not an integer", v.substr(0, 80).c_str()));
        } else if (name == "!!float" && plainStyle) {
            if (!realNumber(v, line) && !(isCoreFloat(v) && real(v, line)))
                refuse(line, format("'!!float %s' is not a number", v.substr(0, 80).c_str()));
        } else if (name == "!!binary") {
            refuse(line, "base64 data (!!binary); no file of this module holds binary data");
        } else {
            refuse(line, format("the tag %s; this module reads !!str, !!int and !!float on plain values",
                                name.c_str()));
        }
    }

private:
    [[noreturn]] void refuse(int line, const std::string& why) { refuseAt(path_, line, why); }

    //! A core-schema integer (decimal, 0x hexadecimal; 0o octal refused): written and true, or false.
    bool integer(const std::string& v, int line)
    {
        const bool signed_ = !v.empty() && (v[0] == '-' || v[0] == '+');
        const size_t from = signed_ ? 1 : 0;
        if (v.size() > from && digitsFrom(v, from) == v.size() - from) {
            if (v.size() - from > 1 && v[from] == '0')
                refuse(line,
                       format("'%s' has a leading zero: YAML 1.2 reads it as decimal, OpenCV's reader as "
                              "octal; write it without the zero",
                              v.c_str()));
            long long magnitude = 0;
            if (!parseMagnitude(v.substr(from), 10, magnitude))
                refuseWrappingInteger(path_, line, v);
            out_.integer(v[0] == '-' ? -magnitude : magnitude, line, v);
            return true;
        }
        const bool hex =
            v.size() > 2 && v[0] == '0' && v[1] == 'x' && std::all_of(v.begin() + 2, v.end(), [](char c) {
                return std::isxdigit(static_cast<unsigned char>(c)) != 0;
            });
        if (hex) {
            long long value = 0;
            if (!parseMagnitude(v.substr(2), 16, value))
                refuseWrappingInteger(path_, line, v);
            out_.integer(value, line, v);
            return true;
        }
        const bool octal = v.size() > 2 && v[0] == '0' && v[1] == 'o' &&
                           std::all_of(v.begin() + 2, v.end(), [](char c) { return c >= '0' && c <= '7'; });
        if (octal)
            refuse(line, format("'%s' is octal to YAML 1.2, which OpenCV's reader does not read: write it in "
                                "decimal",
                                v.c_str()));
        return false;
    }

    //! A core-schema float (with .inf and .nan): written and true, or false. An exponent may be written
    //! with a capital E: OpenCV's reader stops at it, but every other reader takes the same number.
    bool realNumber(const std::string& v, int line)
    {
        const bool negative = !v.empty() && v[0] == '-';
        const std::string unsigned_ = !v.empty() && (v[0] == '-' || v[0] == '+') ? v.substr(1) : v;
        if (unsigned_ == ".inf" || unsigned_ == ".Inf" || unsigned_ == ".INF") {
            out_.real(negative ? -std::numeric_limits<double>::infinity()
                               : std::numeric_limits<double>::infinity(),
                      line);
            return true;
        }
        if (v == ".nan" || v == ".NaN" || v == ".NAN") {
            out_.real(std::numeric_limits<double>::quiet_NaN(), line);
            return true;
        }
        return isCoreFloat(v) && real(v, line);
    }

    bool real(const std::string& v, int line)
    {
        const char* first = v.data() + (v[0] == '+' ? 1 : 0);
        double value = 0;
        const auto result = std::from_chars(first, v.data() + v.size(), value);
        if (result.ec == std::errc::result_out_of_range)
            refuse(line, format("the number %s is beyond the range of a double", v.c_str()));
        if (result.ec != std::errc() || result.ptr != v.data() + v.size())
            return false;
        out_.real(value, line);
        return true;
    }

    String path_;
    OpenCvTextWriter& out_;
};

//! The byte offset of a libyaml mark (its line and column count characters) in `text`.
size_t byteOffsetOf(const std::string& text, size_t from, const yaml_mark_t& mark)
{
    size_t at = from;
    for (size_t line = 0; line < mark.line && at < text.size(); ++line) {
        const size_t newline = text.find('\n', at);
        at = newline == std::string::npos ? text.size() : newline + 1;
    }
    // UTF-8 continuation bytes (10xxxxxx) are no characters of their own.
    for (size_t column = 0; at < text.size() && (column < mark.column || (text[at] & 0xC0) == 0x80); ++at)
        if ((text[at] & 0xC0) != 0x80)
            ++column;
    return at;
}

/** OpenCV's \' escape in `text` from byte `from` written as `replacement` (an escape of the apostrophe the
 * other parser knows); with `oneString`, only up to the end of the double-quoted string `from` is in. Every
 * backslash is taken as an escape of the next byte. Lines stay where they are. */
std::string withApostropheEscapes(const std::string& text, size_t from, bool oneString,
                                  const char* replacement)
{
    std::string out = text.substr(0, from);
    size_t i = from;
    for (; i < text.size() && !(oneString && text[i] == '"'); ++i) {
        if (text[i] == '\\' && i + 1 < text.size()) {
            if (text[i + 1] == '\'')
                out += replacement;
            else
                out.append(text, i, 2);
            ++i;
        } else {
            out += text[i];
        }
    }
    out.append(text, i, std::string::npos);
    return out;
}

/** Parses `text` from byte `from` once into `out`; returns the offset of a backslash where libyaml found
 * an unknown escape and the text has OpenCV's \' there (std::string::npos when it parsed). */
size_t parseYamlOnce(const String& path, const std::string& text, size_t from, int lineOffset,
                     OpenCvTextWriter& out)
{
    YamlParser yaml(text.data() + from, text.size() - from);
    YamlScalarTyper typer(path, out);
    const auto lineOf = [&](const yaml_mark_t& mark) { return static_cast<int>(mark.line) + 1 + lineOffset; };
    std::vector<bool> flow;
    int documents = 0;
    for (;;) {
        YamlEvent e;
        if (!yaml_parser_parse(&yaml.parser, &e.event)) {
            const yaml_parser_t& p = yaml.parser;
            if (p.problem && std::strcmp(p.problem, "found unknown escape character") == 0) {
                const size_t at = byteOffsetOf(text, from, p.problem_mark);
                if (text.compare(at, 2, "\\'") == 0)
                    return at;
            }
            std::string why = p.problem ? p.problem : "malformed YAML";
            if (p.context)
                why += std::string(" ") + p.context + format(" (from line %d)", lineOf(p.context_mark));
            refuseAt(path, lineOf(p.problem_mark), "not valid YAML: " + why);
        }
        e.held = true;
        const yaml_event_t& ev = e.event;
        const int line = lineOf(ev.start_mark);
        switch (ev.type) {
        case YAML_STREAM_END_EVENT:
            if (out.empty())
                CV_Error(Error::StsParseError, "'" + path + "' holds no map (only comments or directives)");
            return std::string::npos;
        case YAML_DOCUMENT_START_EVENT:
            if (++documents > 1)
                refuseAt(path, line, "a second document (this module reads single-document YAML files)");
            break;
        case YAML_ALIAS_EVENT:
            refuseAt(path, line, "an alias (*name): this module's files have no anchors or aliases");
        case YAML_SCALAR_EVENT: {
            const auto& s = ev.data.scalar;
            if (s.anchor)
                refuseAt(path, line, "an anchor (&name): this module's files have no anchors or aliases");
            if (flow.empty())
                refuseAt(path, line, "the root is a single value, not a map");
            const std::string value(reinterpret_cast<const char*>(s.value), s.length);
            const bool plainStyle = s.style == YAML_PLAIN_SCALAR_STYLE;
            const bool untagged = plainStyle ? s.plain_implicit != 0 : s.quoted_implicit != 0;
            if (out.expectsKey()) {
                if (!untagged)
                    refuseAt(path, line, "a tagged key");
                out.key(value, line);
            } else if (!untagged) {
                typer.tagged(value, s.tag ? reinterpret_cast<const char*>(s.tag) : "!", plainStyle, line);
            } else if (plainStyle) {
                typer.plain(value, flow.back(), line);
            } else {
                out.text(value, line);
            }
            break;
        }
        case YAML_SEQUENCE_START_EVENT:
        case YAML_MAPPING_START_EVENT: {
            const bool mapping = ev.type == YAML_MAPPING_START_EVENT;
            if (mapping ? ev.data.mapping_start.anchor : ev.data.sequence_start.anchor)
                refuseAt(path, line, "an anchor (&name): this module's files have no anchors or aliases");
            if (out.expectsKey())
                refuseAt(path, line, "a collection as a key");
            const bool flowStyle = mapping ? ev.data.mapping_start.style == YAML_FLOW_MAPPING_STYLE
                                           : ev.data.sequence_start.style == YAML_FLOW_SEQUENCE_STYLE;
            out.startCollection(mapping, line);
            flow.push_back(flowStyle || (!flow.empty() && flow.back()));
            break;
        }
        case YAML_SEQUENCE_END_EVENT:
        case YAML_MAPPING_END_EVENT:
            out.endCollection();
            flow.pop_back();
            break;
        default:
            break;
        }
    }
}

std::string yamlForOpenCv(const String& path, const std::string& text)
{
    // OpenCV's own header line ("%YAML:1.0") is no YAML directive: libyaml reads from the next line.
    size_t from = 0;
    int lineOffset = 0;
    if (text.compare(0, 5, "%YAML") == 0) {
        const size_t newline = text.find('\n');
        from = newline == std::string::npos ? text.size() : newline + 1;
        lineOffset = 1;
    }
    // OpenCV's writer escapes an apostrophe in a double-quoted string as \', which YAML does not have (a
    // calibration report's notes hold them). libyaml says exactly where it meets one, always in a
    // double-quoted scalar: that scalar's \' become \x27 (YAML's escape of the same character, on the same
    // line) and the text is parsed again. A budget of bytes re-parsed keeps a file full of them from
    // costing more than a second.
    std::string patched;
    const std::string* parsed = &text;
    long long budget = 64LL << 20;
    for (;;) {
        OpenCvTextWriter out(path);
        const size_t escape = parseYamlOnce(path, *parsed, from, lineOffset, out);
        if (escape == std::string::npos)
            return out.finish();
        budget -= static_cast<long long>(parsed->size() - from);
        if (budget < 0)
            refuseAt(path, lineAt(*parsed, escape),
                     "too many double-quoted strings with OpenCV's \\' escape to check");
        patched = withApostropheEscapes(*parsed, escape, true, "\\x27");
        parsed = &patched;
    }
}

// --------------------------------------------------------------------------------------------------
// JSON: nlohmann's events (its parser keeps its state on the heap, not the stack).

class JsonToOpenCv : public nlohmann::json_sax<nlohmann::json>
{
public:
    JsonToOpenCv(const String& path, const std::string& text) : path_(path), text_(text), out_(path) {}

    bool null() override
    {
        out_.null(0);
        return true;
    }
    bool boolean(bool value) override
    {
        out_.boolean(value, 0);
        return true;
    }
    bool number_integer(number_integer_t value) override { return integer(value); }
    bool number_unsigned(number_unsigned_t value) override { return integer(value); }
    bool number_float(number_float_t value, const string_t&) override
    {
        out_.real(value, 0);
        return true;
    }
    bool string(string_t& value) override
    {
        out_.text(value, 0);
        return true;
    }
    bool binary(binary_t&) override { refuseAt(path_, 0, "binary data; no file of this module holds any"); }
    bool key(string_t& value) override
    {
        out_.key(value, 0);
        return true;
    }
    bool start_object(std::size_t) override { return enter(true); }
    bool start_array(std::size_t) override { return enter(false); }
    bool end_object() override { return leave(); }
    bool end_array() override { return leave(); }
    bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception& e) override
    {
        std::string message = e.what();
        // "[json.exception.parse_error.101] parse error at line 3, column 5: ..." without the class.
        const size_t bracket = message.find("] ");
        if (message.compare(0, 1, "[") == 0 && bracket != std::string::npos)
            message.erase(0, bracket + 2);
        CV_Error(Error::StsParseError, "'" + path_ + "' is not valid JSON: " + message);
    }

    std::string finish() { return out_.finish(); }

private:
    bool enter(bool map)
    {
        if (++depth_ > MAX_NESTING_DEPTH)
            refuseDepth(path_, lineAt(text_, offsetBeyondDepth()));
        out_.startCollection(map, 0);
        return true;
    }
    bool leave()
    {
        --depth_;
        out_.endCollection();
        return true;
    }
    //! Written when it fits 32 bits; else refused with the line of its literal (looked up only then).
    template <typename Integer> bool integer(Integer value)
    {
        bool fits = value <= static_cast<Integer>(INT_MAX);
        if constexpr (std::is_signed_v<Integer>)
            fits = fits && value >= INT_MIN;
        if (!fits) {
            const std::string literal = std::to_string(value);
            refuseWrappingInteger(path_, lineAt(text_, offsetOfNumber(literal)), literal);
        }
        out_.integer(static_cast<long long>(value), 0, std::string());
        return true;
    }

    //! Where the text first opens a collection deeper than MAX_NESTING_DEPTH (strings skipped).
    size_t offsetBeyondDepth() const
    {
        int depth = 0;
        bool inString = false;
        for (size_t i = 0; i < text_.size(); ++i) {
            const char c = text_[i];
            if (inString) {
                if (c == '\\')
                    ++i;
                else if (c == '"')
                    inString = false;
            } else if (c == '"') {
                inString = true;
            } else if (c == '[' || c == '{') {
                if (++depth > MAX_NESTING_DEPTH)
                    return i;
            } else if (c == ']' || c == '}') {
                --depth;
            }
        }
        return text_.size();
    }

    /** Where the number `literal` stands alone in the text (not inside a longer number); the text's end if
     * nowhere. Only for the line of an error: a string that holds the same digits may be taken for it. */
    size_t offsetOfNumber(const std::string& literal) const
    {
        const auto partOfNumber = [](char c) { return isAsciiDigit(c) || c == '.' || c == 'e' || c == 'E'; };
        for (size_t at = text_.find(literal); at != std::string::npos; at = text_.find(literal, at + 1)) {
            const size_t end = at + literal.size();
            if ((at == 0 || (!partOfNumber(text_[at - 1]) && text_[at - 1] != '-')) &&
                (end == text_.size() || !partOfNumber(text_[end])))
                return at;
        }
        return text_.size();
    }

    String path_;
    const std::string& text_;
    OpenCvTextWriter out_;
    int depth_ = 0;
};

std::string jsonForOpenCv(const String& path, const std::string& text)
{
    // OpenCV's JSON writer escapes an apostrophe as \', which JSON does not have (its reader takes it). In
    // JSON every backslash belongs to a string, so each \' is such an escape: nlohmann is given \u0027.
    const std::string patched = text.find("\\'") == std::string::npos
                                    ? std::string()
                                    : withApostropheEscapes(text, 0, false, "\\u0027");
    const std::string& parsed = patched.empty() ? text : patched;
    JsonToOpenCv events(path, parsed);
    nlohmann::json::sax_parse(parsed, &events);
    return events.finish();
}

} // namespace

std::string textForOpenCv(const String& path, std::string text)
{
    // A UTF-8 byte-order mark (some Windows editors write one) is not part of the YAML or JSON.
    if (text.compare(0, 3, "\xEF\xBB\xBF") == 0)
        text.erase(0, 3);
    if (text.find('\0') != std::string::npos || text.compare(0, 2, "\xFF\xFE") == 0 ||
        text.compare(0, 2, "\xFE\xFF") == 0)
        CV_Error(Error::StsParseError, "'" + path +
                                           "' holds NUL bytes or a UTF-16 byte-order mark: UTF-16 or UTF-32 "
                                           "text? This module reads UTF-8; save it as UTF-8");
    const size_t first = text.find_first_not_of(" \t\r\n");
    if (first == std::string::npos)
        CV_Error(Error::StsParseError, "'" + path + "' is empty");
    if (text[first] == '<')
        CV_Error(Error::StsParseError, "'" + path + "' looks like XML; this module reads YAML and JSON");
    if (text[first] == '{')
        return jsonForOpenCv(path, text);
    return yamlForOpenCv(path, text);
}

} // namespace detail
} // namespace rawgment
} // namespace cv
