// Validating access to a JSON document: every accessor knows its file and JSON path, so errors
// read "room.json: objects[3].radius: expected a positive number". Objects must be closed with
// finish(), which rejects keys nobody asked for (unknown keys are errors, as in pbrt-v4).
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/math.h"

namespace wedge::io {

class JsonNode {
public:
    JsonNode(const nlohmann::json& value, std::string file, std::string path);

    /// Parses a file; throws wedge::Error naming the file and the line on a syntax error.
    static nlohmann::json parseFile(const std::string& file);
    /// Parses `text`, read from `file`: a syntax error names the line, a number out of double's
    /// range and a key repeated within one object name the JSON path.
    static nlohmann::json parseText(const std::string& text, const std::string& file);

    const std::string& path() const { return m_path; }
    std::string where() const;  // "file: path"
    [[noreturn]] void fail(const std::string& what) const;

    bool isObject() const { return m_value.is_object(); }
    bool isArray() const { return m_value.is_array(); }
    bool has(const std::string& key) const;
    /// A member; required unless a default is supplied through the optional accessors below.
    JsonNode operator[](const std::string& key) const;
    std::optional<JsonNode> optional(const std::string& key) const;
    /// Elements of an array.
    size_t size() const;
    JsonNode operator[](size_t i) const;
    JsonNode operator[](int i) const { return (*this)[size_t(i)]; }
    std::vector<std::string> keys() const;

    /// Numbers as the float a scene stores them in, checked as that float: 1e308 is a finite
    /// double but an infinite float (a light of that radiance rendered NaN pixels), and 1e-50 is a
    /// positive double but a zero float.
    float number() const;
    float positive() const;     // > 0 as a float
    float nonNegative() const;  // >= 0
    int integer() const;
    bool boolean() const;
    std::string string() const;
    Vec3f vec3() const;
    Vec3f color() const;  // vec3 with non-negative components

    /// Rejects keys of this object that were never accessed.
    void finish() const;

private:
    JsonNode member(const std::string& key) const;

    const nlohmann::json& m_value;
    std::string m_file, m_path;
    mutable std::set<std::string> m_seen;
};

}  // namespace wedge::io
