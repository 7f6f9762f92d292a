#include "io/json_reader.h"

#include <cmath>
#include <filesystem>
#include <limits>
#include <set>

#include "core/error.h"
#include "io/text_file.h"

namespace wedge::io {

namespace {
const char* typeName(const nlohmann::json& v) {
    if (v.is_object()) return "an object";
    if (v.is_array()) return "an array";
    if (v.is_string()) return "a string";
    if (v.is_boolean()) return "a boolean";
    if (v.is_number()) return "a number";
    if (v.is_null()) return "null";
    return "an unknown value";
}
}  // namespace

JsonNode::JsonNode(const nlohmann::json& value, std::string file, std::string path)
    : m_value(value), m_file(std::move(file)), m_path(std::move(path)) {}

nlohmann::json JsonNode::parseFile(const std::string& file) {
    if (notARegularFile(file) == "is a directory") throw Error(file, "is a directory, expected a JSON scene file");
    return parseText(readTextFile(file), file);
}

nlohmann::json JsonNode::parseText(const std::string& text, const std::string& file) {
    // RFC 8259 leaves duplicate keys to the parser; nlohmann keeps the last one silently, so a
    // scene with two "fov_y" would render with one of them and no word. The callback sees
    // every key as it is read and keeps the keys of each open object, with the path to it.
    struct Open {
        bool object = false;
        size_t index = 0;  // arrays: the next element's index
        std::string key;   // objects: the key being read
        std::set<std::string> keys;
    };
    std::vector<Open> open;
    auto path = [&] {
        std::string p;
        for (const Open& o : open) {
            if (o.object) p += (p.empty() ? "" : ".") + o.key;
            else p += "[" + std::to_string(o.index) + "]";
        }
        return p;
    };
    auto element = [&] {  // a value (or a nested container) ended: the parent array moves on
        if (!open.empty() && !open.back().object) ++open.back().index;
    };
    using Event = nlohmann::json::parse_event_t;
    nlohmann::json::parser_callback_t callback = [&](int, Event event, nlohmann::json& parsed) {
        switch (event) {
        case Event::object_start:
        case Event::array_start:
            open.emplace_back();
            open.back().object = event == Event::object_start;
            break;
        case Event::object_end:
        case Event::array_end:
            open.pop_back();
            element();
            break;
        case Event::key: {
            Open& o = open.back();
            const std::string& key = parsed.get_ref<const std::string&>();
            o.key = key;
            if (!o.keys.insert(key).second) throw Error(file + ": " + path(), "duplicate key '" + key + "'");
            break;
        }
        case Event::value: element(); break;
        }
        return true;
    };
    try {
        return nlohmann::json::parse(text, callback);
    } catch (const nlohmann::json::parse_error& e) {
        // Translate the byte offset into line:column.
        size_t offset = std::min(e.byte > 0 ? e.byte - 1 : 0, text.size());
        int line = 1, col = 1;
        for (size_t i = 0; i < offset; ++i) {
            if (text[i] == '\n') { ++line; col = 1; } else { ++col; }
        }
        std::string what = e.what();
        auto pos = what.find("syntax error");
        throw Error(file + ":" + std::to_string(line) + ":" + std::to_string(col),
                    "invalid JSON: " + (pos != std::string::npos ? what.substr(pos) : what));
    } catch (const nlohmann::json::out_of_range& e) {
        // A number beyond double's range (1e400): the parser stops there without a position,
        // but the path of the value it was reading is known.
        std::string what = e.what(), where = path();
        auto pos = what.find("number overflow");
        throw Error(where.empty() ? file : file + ": " + where,
                    "invalid JSON: " + (pos != std::string::npos ? what.substr(pos) : what));
    }
}

std::string JsonNode::where() const { return m_path.empty() ? m_file : m_file + ": " + m_path; }
void JsonNode::fail(const std::string& what) const { throw Error(where(), what); }

bool JsonNode::has(const std::string& key) const { return m_value.is_object() && m_value.contains(key); }

JsonNode JsonNode::member(const std::string& key) const {
    std::string p = m_path.empty() ? key : m_path + "." + key;
    if (!m_value.is_object()) fail(std::string("expected an object, got ") + typeName(m_value));
    auto it = m_value.find(key);
    if (it == m_value.end()) throw Error(m_file + ": " + p, "missing required field");
    m_seen.insert(key);
    return JsonNode(*it, m_file, p);
}

JsonNode JsonNode::operator[](const std::string& key) const { return member(key); }

std::optional<JsonNode> JsonNode::optional(const std::string& key) const {
    if (!m_value.is_object()) fail(std::string("expected an object, got ") + typeName(m_value));
    if (!m_value.contains(key)) return std::nullopt;
    return member(key);
}

size_t JsonNode::size() const {
    if (!m_value.is_array()) fail(std::string("expected an array, got ") + typeName(m_value));
    return m_value.size();
}

JsonNode JsonNode::operator[](size_t i) const {
    size();  // type check
    return JsonNode(m_value[i], m_file, m_path + "[" + std::to_string(i) + "]");
}

std::vector<std::string> JsonNode::keys() const {
    if (!m_value.is_object()) fail(std::string("expected an object, got ") + typeName(m_value));
    std::vector<std::string> k;
    for (auto it = m_value.begin(); it != m_value.end(); ++it) k.push_back(it.key());
    return k;
}

float JsonNode::number() const {
    if (!m_value.is_number()) fail(std::string("expected a number, got ") + typeName(m_value));
    const double v = m_value.get<double>();
    // The OBJ/MTL reader's words for the same check (scene/obj_check.cpp).
    if (!(std::abs(v) <= double(std::numeric_limits<float>::max())))
        fail("'" + m_value.dump() + "' is not a finite number within +-3.4e38 (the float it is stored in)");
    return float(v);
}
float JsonNode::positive() const {
    if (!m_value.is_number() || !(m_value.get<double>() > 0)) fail("expected a positive number");
    const float v = number();
    if (!(v > 0)) fail("expected a positive number ('" + m_value.dump() + "' is 0 as the float it is stored in)");
    return v;
}
float JsonNode::nonNegative() const {
    if (!m_value.is_number() || !(m_value.get<double>() >= 0)) fail("expected a non-negative number");
    return number();
}
int JsonNode::integer() const {
    if (!m_value.is_number_integer()) fail(std::string("expected an integer, got ") + typeName(m_value));
    auto v = m_value.get<long long>();
    if (v < INT32_MIN || v > INT32_MAX) fail("integer out of range");
    return int(v);
}
bool JsonNode::boolean() const {
    if (!m_value.is_boolean()) fail(std::string("expected true or false, got ") + typeName(m_value));
    return m_value.get<bool>();
}
std::string JsonNode::string() const {
    if (!m_value.is_string()) fail(std::string("expected a string, got ") + typeName(m_value));
    return m_value.get<std::string>();
}
Vec3f JsonNode::vec3() const {
    if (!m_value.is_array() || m_value.size() != 3) fail("expected an array of 3 numbers");
    Vec3f v;
    for (int i = 0; i < 3; ++i) v[i] = (*this)[size_t(i)].number();
    return v;
}
Vec3f JsonNode::color() const {
    Vec3f v = vec3();
    if (v.x < 0 || v.y < 0 || v.z < 0) fail("expected non-negative colour components");
    return v;
}

void JsonNode::finish() const {
    if (!m_value.is_object()) return;
    for (auto it = m_value.begin(); it != m_value.end(); ++it)
        if (!m_seen.count(it.key())) {
            std::string p = m_path.empty() ? it.key() : m_path + "." + it.key();
            throw Error(m_file + ": " + p, "unknown key");
        }
}

}  // namespace wedge::io
