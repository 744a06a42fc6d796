// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The fuzzer's differential check (differential.hpp): written apart from the library's reader, with its own
// typing and libyaml's document API or nlohmann's DOM, so that the two implementations check each other.
#include "differential.hpp"

#include <opencv2/rawgment/files.hpp>

#include <nlohmann/json.hpp>
#include <yaml.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <new>
#include <regex>
#include <string>

namespace rawgment_fuzz {

namespace {

std::string readAll(const std::string& path)
{
    std::ifstream f(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

//! A libyaml document, freed on every path out.
struct YamlDocument
{
    yaml_parser_t parser;
    yaml_document_t document;
    bool initialized = false, loaded = false;
    explicit YamlDocument(const std::string& text)
    {
        initialized = yaml_parser_initialize(&parser) != 0;
        if (!initialized)
            throw std::bad_alloc();
        yaml_parser_set_input_string(&parser, reinterpret_cast<const unsigned char*>(text.data()),
                                     text.size());
        loaded = yaml_parser_load(&parser, &document) != 0;
    }
    ~YamlDocument()
    {
        if (loaded)
            yaml_document_delete(&document);
        if (initialized)
            yaml_parser_delete(&parser);
    }
    YamlDocument(const YamlDocument&) = delete;
    YamlDocument& operator=(const YamlDocument&) = delete;
};

bool sameReal(double a, double b)
{
    return a == b || (std::isnan(a) && std::isnan(b));
}

//! What coreSchemaType() says of a scalar too long for its patterns: the reader's own typing stands, and
//! the value is compared as a number or a string accordingly.
constexpr int kUntyped = -1;

//! The value YAML 1.2's core schema gives a plain scalar, as the FileNode type it must be read as.
int coreSchemaType(std::string& v, double& number)
{
    static const std::regex decimal("[-+]?[0-9]+"), hex("0x[0-9a-fA-F]+"),
        real("[-+]?(\\.[0-9]+|[0-9]+(\\.[0-9]*)?)([eE][-+]?[0-9]+)?"), inf("[-+]?\\.(inf|Inf|INF)"),
        nan("\\.(nan|NaN|NAN)");
    // std::regex recurses per character: long scalars are strings to both, checked by value alone.
    if (v.size() > 200)
        return kUntyped;
    static const std::regex boolean("true|True|TRUE|false|False|FALSE");
    // A boolean reaches OpenCV as the string "true" or "false", which only the flag reader takes.
    if (std::regex_match(v, boolean)) {
        v = v[0] == 't' || v[0] == 'T' ? "true" : "false";
        return cv::FileNode::STRING;
    }
    if (std::regex_match(v, decimal) || std::regex_match(v, hex)) {
        number = double(std::strtoll(v.c_str(), nullptr, v.size() > 1 && v[1] == 'x' ? 16 : 10));
        return cv::FileNode::INT;
    }
    if (std::regex_match(v, inf)) {
        number = v[0] == '-' ? -HUGE_VAL : HUGE_VAL;
        return cv::FileNode::REAL;
    }
    if (std::regex_match(v, nan)) {
        number = std::nan("");
        return cv::FileNode::REAL;
    }
    if (std::regex_match(v, real)) {
        number = std::strtod(v.c_str(), nullptr);
        return cv::FileNode::REAL;
    }
    return cv::FileNode::STRING;
}

std::string compareYaml(yaml_document_t& doc, const yaml_node_t* node, const cv::FileNode& fn,
                        const std::string& at)
{
    if (node->type == YAML_MAPPING_NODE) {
        if (!fn.isMap())
            return at + ": a map to libyaml, not to OpenCV";
        const auto& pairs = node->data.mapping.pairs;
        if (size_t(pairs.top - pairs.start) != fn.size())
            return at + cv::format(": %d keys to libyaml, %d to OpenCV", int(pairs.top - pairs.start),
                                   int(fn.size()));
        for (const yaml_node_pair_t* p = pairs.start; p < pairs.top; ++p) {
            const yaml_node_t* key = yaml_document_get_node(&doc, p->key);
            const std::string name(reinterpret_cast<const char*>(key->data.scalar.value),
                                   key->data.scalar.length);
            const std::string why =
                compareYaml(doc, yaml_document_get_node(&doc, p->value), fn[name], at + "." + name);
            if (!why.empty())
                return why;
        }
        return std::string();
    }
    if (node->type == YAML_SEQUENCE_NODE) {
        if (!fn.isSeq())
            return at + ": a list to libyaml, not to OpenCV";
        const auto& items = node->data.sequence.items;
        if (size_t(items.top - items.start) != fn.size())
            return at + cv::format(": %d items to libyaml, %d to OpenCV", int(items.top - items.start),
                                   int(fn.size()));
        for (int k = 0; k < int(items.top - items.start); ++k) {
            const std::string why = compareYaml(doc, yaml_document_get_node(&doc, items.start[k]), fn[k],
                                                at + cv::format("[%d]", k));
            if (!why.empty())
                return why;
        }
        return std::string();
    }
    std::string value(reinterpret_cast<const char*>(node->data.scalar.value), node->data.scalar.length);
    const std::string tag = node->tag ? reinterpret_cast<const char*>(node->tag) : "";
    double number = 0;
    int type = cv::FileNode::STRING;
    if (tag == YAML_INT_TAG || tag == YAML_FLOAT_TAG) {
        if (coreSchemaType(value, number) == kUntyped)
            number = std::strtod(value.c_str(), nullptr);
        type = tag == YAML_INT_TAG ? cv::FileNode::INT : cv::FileNode::REAL;
    } else if (node->data.scalar.style == YAML_PLAIN_SCALAR_STYLE)
        type = coreSchemaType(value, number); // libyaml's document tags an untagged scalar !!str too
    if (type == kUntyped) {
        type = fn.isString() ? int(cv::FileNode::STRING) : fn.type();
        number = std::strtod(value.c_str(), nullptr);
    }
    if (type != fn.type())
        return at + cv::format(": '%s' is of type %d to YAML 1.2 and %d to OpenCV",
                               value.substr(0, 60).c_str(), type, fn.type());
    if (type == cv::FileNode::STRING && value != fn.string())
        return at + ": '" + value.substr(0, 60) + "' to libyaml, '" + fn.string().substr(0, 60) +
               "' to OpenCV";
    if (type != cv::FileNode::STRING && !sameReal(number, fn.real()))
        return at + cv::format(": %.17g to libyaml, %.17g to OpenCV", number, fn.real());
    return std::string();
}

std::string compareJson(const nlohmann::json& j, const cv::FileNode& fn, const std::string& at)
{
    if (j.is_object()) {
        if (!fn.isMap())
            return at + ": a map to nlohmann-json, not to OpenCV";
        size_t members = 0;
        for (auto it = j.begin(); it != j.end(); ++it) {
            if (it.value().is_null()) {
                if (!fn[it.key()].empty())
                    return at + "." + it.key() + ": a null read as a value";
                continue;
            }
            ++members;
            const std::string why = compareJson(it.value(), fn[it.key()], at + "." + it.key());
            if (!why.empty())
                return why;
        }
        return members == fn.size() ? std::string() : at + ": another number of keys to OpenCV";
    }
    if (j.is_array()) {
        if (!fn.isSeq() || j.size() != fn.size())
            return at + ": another list to OpenCV";
        for (size_t k = 0; k < j.size(); ++k) {
            const std::string why = compareJson(j[k], fn[int(k)], at + cv::format("[%d]", int(k)));
            if (!why.empty())
                return why;
        }
        return std::string();
    }
    if (j.is_string())
        return fn.isString() && fn.string() == j.get<std::string>() ? std::string() : at + ": another string";
    if (j.is_boolean())
        return fn.isString() && fn.string() == (j.get<bool>() ? "true" : "false") ? std::string()
                                                                                  : at + ": another boolean";
    if (j.is_number_float())
        return fn.isReal() && sameReal(fn.real(), j.get<double>()) ? std::string() : at + ": another real";
    if (j.is_number())
        return fn.isInt() && double(int(fn)) == j.get<double>() ? std::string() : at + ": another integer";
    return at + ": a value nlohmann-json has and OpenCV does not";
}

} // namespace

/** Opens `path` with the module's reader: an error must name the file; an opened text must hold the values
 * the independent parse reads. Returns the complaint, empty when it holds. */
std::string differentialCheck(const std::string& path)
{
    cv::FileStorage fs;
    try {
        fs = cv::rawgment::openFileStorageForReading(path, "fuzz input");
    } catch (const cv::Exception& e) {
        return e.err.find(path) == std::string::npos ? "the reader refused without naming the file: " + e.err
                                                     : std::string();
    }
    std::string text = readAll(path);
    // OpenCV's writers escape ' as \', which neither YAML nor JSON has, and libyaml's documents tag every
    // untagged scalar !!str: texts with either are not compared.
    if (text.find("\\'") != std::string::npos || text.find("!!str") != std::string::npos)
        return std::string();
    if (text.compare(0, 3, "\xEF\xBB\xBF") == 0)
        text.erase(0, 3);
    // JSON is text that starts with a brace, decided before OpenCV's %YAML line is taken off (a YAML file
    // may hold a flow map after it), as the reader decides.
    const size_t first = text.find_first_not_of(" \t\r\n");
    const bool json = first != std::string::npos && text[first] == '{';
    if (text.compare(0, 5, "%YAML") == 0)
        text.erase(0, std::min(text.size(), text.find('\n')));
    if (json) {
        const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
        if (j.is_discarded())
            return "the reader opened a text nlohmann-json refuses";
        return compareJson(j, fs.root(), "root");
    }
    YamlDocument doc(text);
    if (!doc.loaded)
        return "the reader opened a text libyaml refuses";
    const yaml_node_t* root = yaml_document_get_root_node(&doc.document);
    return root ? compareYaml(doc.document, root, fs.root(), "root") : "the reader opened an empty YAML text";
}

} // namespace rawgment_fuzz
