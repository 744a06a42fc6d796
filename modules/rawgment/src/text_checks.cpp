// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The files topic (files.hpp), its text checks: what every YAML/JSON text passes before OpenCV's parser
// sees it. libyaml or nlohmann-json parses it first, in the calling thread and without recursion, and the
// structure OpenCV 4.6's reader loops forever on is refused; openFileStorageForReading() (files.cpp)
// calls them.
#include "precomp.hpp"

#include <algorithm>
#include <cctype>
#include <climits>
#include <cstring>
#include <sstream>

#include <nlohmann/json.hpp>
#include <yaml.h>

namespace cv {
namespace rawgment {
namespace detail {
namespace {

//! Whether a plain scalar is an integer literal, [+-]?[0-9]+, as OpenCV's readers would take it.
bool isIntegerLiteral(const char* s, size_t n)
{
    size_t i = n > 0 && (s[0] == '-' || s[0] == '+') ? 1 : 0;
    if (i == n)
        return false;
    for (; i < n; ++i)
        if (s[i] < '0' || s[i] > '9')
            return false;
    return true;
}

bool fitsInt(const std::string& literal)
{
    // More than ten significant digits never fit; fewer are parsed exactly.
    size_t first = literal.find_first_not_of("+-");
    first = literal.find_first_not_of('0', first);
    if (first == std::string::npos)
        return true;
    if (literal.size() - first > 10)
        return false;
    const long long value = std::strtoll(literal.c_str(), nullptr, 10);
    return value >= INT_MIN && value <= INT_MAX;
}

[[noreturn]] void refuseWrappingInteger(const String& path, int line, const std::string& literal)
{
    CV_Error(
        Error::StsParseError,
        format("'%s' line %d: the integer %s does not fit 32 bits (OpenCV's reader would wrap it); write "
               "it as a real (%s.0) if that is the value meant",
               path.c_str(), line, literal.c_str(), literal.c_str()));
}

[[noreturn]] void refuseDepth(const String& path, int line)
{
    CV_Error(Error::StsParseError,
             format("'%s' line %d: collections nested more than %d levels deep; no file of this module nests "
                    "so deep (OpenCV's recursive reader would overflow the stack)",
                    path.c_str(), line, MAX_NESTING_DEPTH));
}

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

//! The line (1-based) of byte `offset` of `text`.
int lineAt(const std::string& text, size_t offset)
{
    offset = std::min(offset, text.size());
    return 1 + static_cast<int>(
                   std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(offset), '\n'));
}

/** A JSON validator's events (nlohmann's SAX interface): the depth and 32-bit integers checked as the
 * text streams by, nothing stored. nlohmann's parser keeps its own state on the heap, not the stack. */
class JsonChecks : public nlohmann::json_sax<nlohmann::json>
{
public:
    enum class Stop
    {
        NONE,
        SYNTAX,
        DEPTH,
        INTEGER
    };
    Stop stop = Stop::NONE;
    std::string message;
    std::string literal;
    bool null() override { return true; }
    bool boolean(bool) override { return true; }
    bool number_integer(number_integer_t value) override
    {
        return value >= INT_MIN && value <= INT_MAX ? true : wraps(std::to_string(value));
    }
    bool number_unsigned(number_unsigned_t value) override
    {
        return value <= static_cast<number_unsigned_t>(INT_MAX) ? true : wraps(std::to_string(value));
    }
    bool number_float(number_float_t, const string_t&) override { return true; }
    bool string(string_t&) override { return true; }
    bool binary(binary_t&) override { return true; }
    bool key(string_t&) override { return true; }
    bool start_object(std::size_t) override { return enter(); }
    bool start_array(std::size_t) override { return enter(); }
    bool end_object() override { return leave(); }
    bool end_array() override { return leave(); }
    bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception& e) override
    {
        stop = Stop::SYNTAX;
        message = e.what();
        // "[json.exception.parse_error.101] parse error at line 3, column 5: ..." without the class.
        const size_t bracket = message.find("] ");
        if (message.compare(0, 1, "[") == 0 && bracket != std::string::npos)
            message.erase(0, bracket + 2);
        return false;
    }

private:
    int depth_ = 0;
    bool enter()
    {
        if (++depth_ <= MAX_NESTING_DEPTH)
            return true;
        stop = Stop::DEPTH;
        return false;
    }
    bool leave()
    {
        --depth_;
        return true;
    }
    bool wraps(std::string value)
    {
        stop = Stop::INTEGER;
        literal = std::move(value);
        return false;
    }
};

//! Where the JSON text first opens a collection deeper than MAX_NESTING_DEPTH (strings skipped).
size_t offsetBeyondDepth(const std::string& text)
{
    int depth = 0;
    bool inString = false;
    for (size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
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
    return text.size();
}

/** Where the number `literal` stands alone in the JSON text (not inside a longer number); the text's end if
 * nowhere. Only for the line of an error: a string that holds the same digits may be taken for it. */
size_t offsetOfNumber(const std::string& text, const std::string& literal)
{
    const auto partOfNumber = [](char c) {
        return (c >= '0' && c <= '9') || c == '.' || c == 'e' || c == 'E';
    };
    for (size_t at = text.find(literal); at != std::string::npos; at = text.find(literal, at + 1)) {
        const size_t end = at + literal.size();
        if ((at == 0 || (!partOfNumber(text[at - 1]) && text[at - 1] != '-')) &&
            (end == text.size() || !partOfNumber(text[end])))
            return at;
    }
    return text.size();
}

void appendUtf8(std::string& out, unsigned codePoint)
{
    if (codePoint < 0x80) {
        out += static_cast<char>(codePoint);
    } else if (codePoint < 0x800) {
        out += static_cast<char>(0xC0 | (codePoint >> 6));
        out += static_cast<char>(0x80 | (codePoint & 0x3F));
    } else if (codePoint < 0x10000) {
        out += static_cast<char>(0xE0 | (codePoint >> 12));
        out += static_cast<char>(0x80 | ((codePoint >> 6) & 0x3F));
        out += static_cast<char>(0x80 | (codePoint & 0x3F));
    } else {
        out += static_cast<char>(0xF0 | (codePoint >> 18));
        out += static_cast<char>(0x80 | ((codePoint >> 12) & 0x3F));
        out += static_cast<char>(0x80 | ((codePoint >> 6) & 0x3F));
        out += static_cast<char>(0x80 | (codePoint & 0x3F));
    }
}

unsigned hex4(const std::string& text, size_t at)
{
    return static_cast<unsigned>(std::stoul(text.substr(at, 4), nullptr, 16));
}

} // namespace

void rejectUnsupportedStructure(const String& path, const std::string& text)
{
    const size_t first = text.find_first_not_of(" \t\r\n");
    if (first == std::string::npos)
        CV_Error(Error::StsParseError, "'" + path + "' is empty");
    if (text[first] == '<')
        CV_Error(Error::StsParseError, "'" + path + "' looks like XML; this module reads YAML and JSON");
    if (text[first] == '{')
        return; // JSON
    // OpenCV 4.6's YAML parser never returns when a stream goes on after its first document with a '-'
    // that does not start '---' (test/fuzz found three such files, for example "---[][  -"). The files
    // of this module hold one document whose root is a block collection starting a line of its own at
    // column 0, which ends only at the end of the file: anything else is refused before OpenCV sees it.
    std::istringstream lines(text);
    std::string line;
    bool header = false, content = false;
    for (int number = 1; std::getline(lines, line); ++number) {
        const size_t start = line.find_first_not_of(" \r");
        if (start == std::string::npos || line[start] == '#')
            continue;
        const auto refuse = [&](const char* why) {
            CV_Error(Error::StsParseError, format("'%s' line %d: %s (this module reads single-document YAML "
                                                  "files whose root is a block map or list at column 0)",
                                                  path.c_str(), number, why));
        };
        const bool marker = line.compare(start, 3, "---") == 0 || line.compare(start, 3, "...") == 0;
        if (!content) {
            if (line[start] == '%')
                continue;
            if (line.compare(start, 3, "---") == 0 && !header) {
                const size_t rest = line.find_first_not_of(" \r", start + 3);
                if (start != 0 || (rest != std::string::npos && line[rest] != '#'))
                    refuse("content on the document's '---' line");
                header = true;
                continue;
            }
            if (marker)
                refuse("a second document marker");
            if (start != 0)
                refuse("the root collection does not start at column 0");
            if (line[start] == '[' || line[start] == '{')
                refuse("the root is a flow collection");
            content = true;
        }
        // At column 0 only the root's own keys or items: anything else ends the root early, and OpenCV's
        // reader loops forever when a '-' follows (test/fuzz found "!: -.\n{  -").
        const unsigned char lead = static_cast<unsigned char>(line[start]);
        if (start == 0 && !marker && !std::isalnum(lead) && lead != '_' && lead != '"' && lead != '\'' &&
            !(lead == '-' && (line.size() == 1 || line[1] == ' ' || line[1] == '\r')))
            refuse("a line at column 0 that is neither a key nor an item of the root collection");
        if (marker)
            refuse("a document marker after the first document's content");
    }
}

namespace {

/** OpenCV's \\' escapes in `text` from byte `from` written as \\" (the same length, and a quote inside the
 * string for a parser that knows only YAML's or JSON's escapes); with `oneString`, only up to the end of the
 * double-quoted string `from` is in. Every backslash is taken as an escape of the next byte. */
void apostropheEscapesAsQuotes(std::string& text, size_t from, bool oneString)
{
    for (size_t i = from; i + 1 < text.size() && !(oneString && text[i] == '"'); ++i)
        if (text[i] == '\\') {
            if (text[i + 1] == '\'')
                text[i + 1] = '"';
            ++i;
        }
}

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

/** Parses `text` from byte `from` once; returns the offset of a backslash where libyaml found an unknown
 * escape and the text has OpenCV's \' there (std::string::npos when it parsed or failed otherwise). */
size_t validateYamlOnce(const String& path, const std::string& text, size_t from, int lineOffset);

} // namespace

void validateYaml(const String& path, const std::string& text)
{
    // OpenCV's own header line ("%YAML:1.0") is no YAML directive: libyaml reads from the next line.
    size_t from = 0;
    int lineOffset = 0;
    if (text.compare(0, 5, "%YAML") == 0) {
        const size_t newline = text.find('\n');
        from = newline == std::string::npos ? text.size() : newline + 1;
        lineOffset = 1;
    }
    // OpenCV's writer escapes an apostrophe in a double-quoted string as \', which YAML does not have
    // (a calibration report's notes hold them). libyaml says exactly where it meets one, always in a
    // double-quoted scalar: that scalar's \' become \" (the same length, so lines and columns stay) and
    // the text is parsed again. A budget of bytes re-parsed keeps a file full of them from costing
    // more than a second.
    std::string patched;
    const std::string* parsed = &text;
    long long budget = 64LL << 20;
    for (;;) {
        const size_t escape = validateYamlOnce(path, *parsed, from, lineOffset);
        if (escape == std::string::npos)
            return;
        budget -= static_cast<long long>(parsed->size() - from);
        if (budget < 0)
            CV_Error(Error::StsParseError,
                     format("'%s' line %d: too many double-quoted strings with OpenCV's \\' escape to check",
                            path.c_str(), lineAt(*parsed, escape)));
        if (parsed == &text) {
            patched = text;
            parsed = &patched;
        }
        apostropheEscapesAsQuotes(patched, escape, true);
    }
}

namespace {

size_t validateYamlOnce(const String& path, const std::string& text, size_t from, int lineOffset)
{
    YamlParser yaml(text.data() + from, text.size() - from);
    const auto lineOf = [&](const yaml_mark_t& mark) { return static_cast<int>(mark.line) + 1 + lineOffset; };
    const auto refuse = [&](int line, const std::string& why) {
        CV_Error(Error::StsParseError, format("'%s' line %d: %s", path.c_str(), line, why.c_str()));
    };
    int depth = 0, documents = 0;
    bool root = false;
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
            refuse(lineOf(p.problem_mark), "not valid YAML: " + why);
        }
        e.held = true;
        const yaml_event_t& ev = e.event;
        const int line = lineOf(ev.start_mark);
        switch (ev.type) {
        case YAML_STREAM_END_EVENT:
            if (!root)
                CV_Error(Error::StsParseError, "'" + path + "' holds no map (only comments or directives)");
            return std::string::npos;
        case YAML_DOCUMENT_START_EVENT:
            if (++documents > 1)
                refuse(line, "a second document (this module reads single-document YAML files)");
            break;
        case YAML_ALIAS_EVENT:
            refuse(line, "an alias (*name): OpenCV's reader has no anchors or aliases");
            break;
        case YAML_SCALAR_EVENT:
            if (ev.data.scalar.anchor)
                refuse(line, "an anchor (&name): OpenCV's reader has no anchors or aliases");
            if (depth == 0)
                refuse(line, "the root is a single value, not a map (this module reads single-document YAML "
                             "files whose root is a block map or list at column 0)");
            // An untagged plain scalar; "!!str 4294967297" is a string to OpenCV too.
            if (ev.data.scalar.style == YAML_PLAIN_SCALAR_STYLE && ev.data.scalar.plain_implicit) {
                const char* value = reinterpret_cast<const char*>(ev.data.scalar.value);
                const size_t length = ev.data.scalar.length;
                if (isIntegerLiteral(value, length) && !fitsInt(std::string(value, length)))
                    refuseWrappingInteger(path, line, std::string(value, length));
            }
            break;
        case YAML_SEQUENCE_START_EVENT:
        case YAML_MAPPING_START_EVENT: {
            const bool mapping = ev.type == YAML_MAPPING_START_EVENT;
            const yaml_char_t* anchor =
                mapping ? ev.data.mapping_start.anchor : ev.data.sequence_start.anchor;
            if (anchor)
                refuse(line, "an anchor (&name): OpenCV's reader has no anchors or aliases");
            if (depth == 0) {
                const bool flow = mapping ? ev.data.mapping_start.style == YAML_FLOW_MAPPING_STYLE
                                          : ev.data.sequence_start.style == YAML_FLOW_SEQUENCE_STYLE;
                if (flow)
                    refuse(line, "the root is a flow collection (this module reads single-document YAML "
                                 "files whose root is a block map or list at column 0)");
                if (ev.start_mark.column != 0)
                    refuse(line, "the root collection does not start at column 0 (this module reads "
                                 "single-document YAML files whose root is a block map or list at column 0)");
                root = true;
            }
            if (++depth > MAX_NESTING_DEPTH)
                refuseDepth(path, line);
            break;
        }
        case YAML_SEQUENCE_END_EVENT:
        case YAML_MAPPING_END_EVENT:
            --depth;
            break;
        default:
            break;
        }
    }
}

} // namespace

std::string validateJson(const String& path, std::string text)
{
    // OpenCV's JSON writer escapes an apostrophe as \', which JSON does not have (its reader takes it).
    // In JSON every backslash belongs to a string, so each \' is such an escape: the validator is given
    // \" in its place (the same length and string), and OpenCV the text as it is.
    std::string forValidator;
    if (text.find("\\'") != std::string::npos) {
        forValidator = text;
        apostropheEscapesAsQuotes(forValidator, 0, false);
    }
    JsonChecks checks;
    nlohmann::json::sax_parse(forValidator.empty() ? text : forValidator, &checks);
    switch (checks.stop) {
    case JsonChecks::Stop::SYNTAX:
        CV_Error(Error::StsParseError, "'" + path + "' is not valid JSON: " + checks.message);
    case JsonChecks::Stop::DEPTH:
        refuseDepth(path, lineAt(text, offsetBeyondDepth(text)));
    case JsonChecks::Stop::INTEGER:
        refuseWrappingInteger(path, lineAt(text, offsetOfNumber(text, checks.literal)), checks.literal);
    case JsonChecks::Stop::NONE:
        break;
    }
    // OpenCV's JSON reader knows the escapes \" \\ \' \n \r \t \b \f but not \u or \/, which JSON allows
    // and common writers use (Python's json.dump writes every non-ASCII letter as \u00f8): those are
    // written out as UTF-8. The text is valid JSON here, so every backslash is an escape in a string.
    if (text.find("\\u") == std::string::npos && text.find("\\/") == std::string::npos)
        return text;
    std::string out;
    out.reserve(text.size());
    for (size_t i = 0; i < text.size(); ++i) {
        if (text[i] != '\\') {
            out += text[i];
            continue;
        }
        const char kind = text[i + 1];
        if (kind == '/') {
            out += '/';
            ++i;
            continue;
        }
        if (kind != 'u') {
            out.append(text, i, 2);
            ++i;
            continue;
        }
        unsigned codePoint = hex4(text, i + 2);
        size_t length = 6;
        // A high surrogate is followed by its low one (the validator has checked the pair).
        if (codePoint >= 0xD800 && codePoint <= 0xDBFF) {
            codePoint = 0x10000 + ((codePoint - 0xD800) << 10) + (hex4(text, i + 8) - 0xDC00);
            length = 12;
        }
        if (codePoint == 0)
            CV_Error(Error::StsParseError,
                     format("'%s' line %d: a \\u0000 (NUL) in a string; OpenCV's strings "
                            "end at a NUL",
                            path.c_str(), lineAt(text, i)));
        if (codePoint == '"' || codePoint == '\\')
            out += '\\';
        if (codePoint == '\n')
            out += "\\n";
        else if (codePoint == '\r')
            out += "\\r";
        else
            appendUtf8(out, codePoint);
        i += length - 1;
    }
    return out;
}

} // namespace detail
} // namespace rawgment
} // namespace cv
