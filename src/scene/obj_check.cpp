#include "scene/obj_check.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include "core/error.h"

namespace wedge::scene {

namespace {

/// Splits text into lines, without '\n' or a trailing '\r', as tinyobjloader does.
class LineReader {
public:
    explicit LineReader(std::string_view text) : m_text(text) {}
    bool next(std::string_view& line) {
        if (m_pos >= m_text.size()) return false;
        size_t end = m_text.find('\n', m_pos);
        if (end == std::string_view::npos) end = m_text.size();
        line = m_text.substr(m_pos, end - m_pos);
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        m_pos = end + 1;
        ++m_number;
        return true;
    }
    size_t number() const { return m_number; }

private:
    std::string_view m_text;
    size_t m_pos = 0, m_number = 0;
};

bool isBlank(char c) { return c == ' ' || c == '\t'; }

/// Fills `out` (cleared, its capacity kept: a large OBJ has a million lines) with the tokens
/// before one that starts with '#', a comment some exporters append (`v 1 2 3 # corner`).
/// Inside a token '#' is not a comment: tinyobjloader reads `5#b` as 0, so it must fail. Nor
/// after a face's corners, which tinyobjloader rejects (`comments` false).
void splitTokens(std::string_view line, std::vector<std::string_view>& out, bool comments = true) {
    out.clear();
    size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && isBlank(line[i])) ++i;
        size_t start = i;
        while (i < line.size() && !isBlank(line[i])) ++i;
        if (comments && i > start && line[start] == '#') return;
        if (i > start) out.push_back(line.substr(start, i - start));
    }
}

/// from_chars takes no leading '+', which tinyobjloader (and strtod) accept.
std::string_view withoutPlus(std::string_view token) {
    if (token.size() > 1 && token[0] == '+' && token[1] != '-') token.remove_prefix(1);
    return token;
}

/// A whole token as a finite float ("+1.5", ".5", "1e-3"; not "nan", "inf", "1e39", "0.5.5", "1,5").
bool parseNumber(std::string_view token, double& value) {
    token = withoutPlus(token);
    const char* end = token.data() + token.size();
    auto [ptr, ec] = std::from_chars(token.data(), end, value, std::chars_format::general);
    // Within float's range: tinyobjloader and the renderer keep floats.
    return ec == std::errc() && ptr == end && std::abs(value) <= double(std::numeric_limits<float>::max());
}

bool parseInteger(std::string_view token, long long& value) {
    token = withoutPlus(token);
    const char* end = token.data() + token.size();
    auto [ptr, ec] = std::from_chars(token.data(), end, value);
    return ec == std::errc() && ptr == end;
}

struct Source {
    const std::string& where;  // the scene file's field that names the file
    const std::string& path;
};

[[noreturn]] void fail(const Source& src, size_t line, const std::string& what) {
    throw Error(src.where, "'" + src.path + "' line " + std::to_string(line) + ": " + what);
}

std::string quoted(std::string_view s) {
    constexpr size_t kShown = 40;
    std::string out(1, '\'');
    out.append(s.substr(0, kShown)).append(s.size() > kShown ? "...'" : "'");
    return out;
}

/// The tokens after the keyword must be `min` to `max` finite numbers.
void expectNumbers(const std::vector<std::string_view>& t, size_t min, size_t max, const char* shape,
                   const Source& src, size_t line) {
    const std::string keyword(t[0]);
    for (size_t i = 1; i < t.size() && i <= max; ++i) {
        double v;
        if (!parseNumber(t[i], v))
            fail(src, line, "`" + keyword + "` expects " + shape + ", and " + quoted(t[i]) + " is not a finite number within +-3.4e38");
    }
    const size_t n = t.size() - 1;
    if (n < min || n > max)
        fail(src, line, "`" + keyword + "` expects " + shape + ", got " + std::to_string(n) + " value" + (n == 1 ? "" : "s"));
}

}  // namespace

std::string checkObjText(std::string_view text, const std::string& where, const std::string& file) {
    // The statements of the OBJ format (Wavefront's appendix B1), free-form geometry included.
    static const std::set<std::string_view> kKnown = {
        "v",     "vt",    "vn",      "vp",     "cstype", "deg",       "bmat",      "step",  "p",     "l",
        "f",     "fo",    "curv",    "curv2",  "surf",   "parm",      "trim",      "hole",  "scrv",  "sp",
        "end",   "con",   "g",       "s",      "mg",     "o",         "bevel",     "c_interp", "d_interp", "lod",
        "usemtl", "usemap", "mtllib", "maplib", "shadow_obj", "trace_obj", "ctech", "stech", "call", "csh"};
    const Source src{where, file};
    size_t unknown = 0, firstUnknownLine = 0;
    std::string firstUnknown;
    LineReader reader(text);
    std::string_view line;
    std::vector<std::string_view> t;
    long long counts[3] = {0, 0, 0};  // v, vt, vn defined so far
    // The largest positive index of each kind, where it is: checked against the file's totals at
    // the end, since tinyobjloader resolves them after reading (a face may name a later vertex).
    long long largest[3] = {0, 0, 0};
    size_t largestLine[3] = {0, 0, 0};
    std::string largestCorner[3];
    static const char* kElement[3] = {"vertex", "texture coordinate", "normal"};
    static const char* kStatement[3] = {"v", "vt", "vn"};
    while (reader.next(line)) {
        const size_t n = reader.number();
        size_t i = 0;
        while (i < line.size() && isBlank(line[i])) ++i;
        if (i >= line.size() || line[i] == '#') continue;
        size_t end = i;
        while (end < line.size() && !isBlank(line[end])) ++end;
        const std::string_view keyword = line.substr(i, end - i);
        // Only the statements whose numbers wedge relies on are split and checked.
        if (keyword != "v" && keyword != "vn" && keyword != "vt" && keyword != "f") {
            if (!kKnown.count(keyword) && unknown++ == 0) {
                firstUnknownLine = n;
                firstUnknown = quoted(keyword);
            }
            continue;
        }
        splitTokens(line, t, line[i] == 'v');
        if (t[0] == "v") {
            expectNumbers(t, 3, 7, "3 to 7 numbers (x y z [w] [r g b])", src, n);
            ++counts[0];
        } else if (t[0] == "vn") {
            expectNumbers(t, 3, 3, "3 numbers (x y z)", src, n);
            ++counts[2];
        } else if (t[0] == "vt") {
            expectNumbers(t, 1, 3, "1 to 3 numbers (u [v] [w])", src, n);
            ++counts[1];
        } else if (t[0] == "f") {
            if (t.size() < 4)
                fail(src, n, "a face needs at least 3 corners, got " + std::to_string(t.size() - 1));
            for (size_t k = 1; k < t.size(); ++k) {
                // v, v/t, v//n or v/t/n
                std::string_view corner = t[k];
                std::string_view part[3];
                size_t parts = 0, start = 0;
                for (size_t c = 0; c <= corner.size() && parts < 3; ++c)
                    if (c == corner.size() || corner[c] == '/') {
                        part[parts++] = corner.substr(start, c - start);
                        start = c + 1;
                    }
                const bool shapeOk = start > corner.size() && !part[0].empty() && !(parts == 2 && part[1].empty()) &&
                                     !(parts == 3 && part[2].empty());
                if (!shapeOk)
                    fail(src, n, "face corner " + quoted(corner) + " is not v, v/t, v//n or v/t/n");
                for (size_t p = 0; p < parts; ++p) {
                    if (part[p].empty()) continue;  // the t of v//n
                    long long index;
                    if (!parseInteger(part[p], index) || index == 0)
                        fail(src, n, "face corner " + quoted(corner) +
                                         (parts > 1 ? ": " + quoted(part[p]) : std::string()) +
                                         " is not a non-zero integer index");
                    if (-index > counts[p])  // negative: counted back from the last one so far
                        fail(src, n, "face corner " + quoted(corner) + " refers to " + kElement[p] + " " +
                                          std::to_string(index) + ", but " + std::to_string(counts[p]) + " `" +
                                          kStatement[p] + (counts[p] == 1 ? "` line precedes it" : "` lines precede it"));
                    if (index > largest[p]) {
                        largest[p] = index;
                        largestLine[p] = n;
                        largestCorner[p] = quoted(corner);
                    }
                }
            }
        }
    }
    for (int p = 0; p < 3; ++p)
        if (largest[p] > counts[p])
            fail(src, largestLine[p], "face corner " + largestCorner[p] + " refers to " + kElement[p] + " " +
                                          std::to_string(largest[p]) + ", but the file has " + std::to_string(counts[p]) +
                                          " `" + kStatement[p] + (counts[p] == 1 ? "` line" : "` lines"));
    if (unknown == 0) return "";
    // tinyobjloader skips what it does not know; a mistyped `v` or `f` would lose geometry.
    return "'" + file + "' line " + std::to_string(firstUnknownLine) + ": " + firstUnknown +
           " is not an OBJ statement" +
           (unknown > 1 ? " (nor are the first words of " + std::to_string(unknown - 1) + " more lines)" : "") +
           "; skipped";
}

std::vector<std::string> mtlFilesOf(std::string_view objText, const std::string& searchDir) {
    std::vector<std::string> dirs;
    if (!searchDir.empty()) {  // tinyobjloader splits its search path at ':'
        std::istringstream in(searchDir);
        for (std::string d; std::getline(in, d, ':');) dirs.push_back(d);
    }
    auto join = [](const std::string& dir, const std::string& name) {
        if (dir.empty()) return name;
        return dir.back() == '/' ? dir + name : dir + "/" + name;
    };
    auto locate = [&](const std::string& name) -> std::string {
        if (dirs.empty()) return std::ifstream(name) ? name : "";
        for (const std::string& d : dirs)
            if (std::ifstream(join(d, name))) return join(d, name);
        return "";
    };

    std::vector<std::string> files;
    std::set<std::string> read;  // by the name the statement gives, as tinyobjloader keeps them
    LineReader reader(objText);
    std::string_view line;
    while (reader.next(line)) {
        size_t i = 0;
        while (i < line.size() && isBlank(line[i])) ++i;
        line.remove_prefix(i);
        if (line.size() < 7 || line.substr(0, 6) != "mtllib" || !isBlank(line[6])) continue;
        // Names split at spaces, a backslash escaping the next character (tinyobjloader's rule).
        std::vector<std::string> names;
        std::string name;
        bool escaping = false;
        for (char c : line.substr(7)) {
            if (escaping) {
                escaping = false;
            } else if (c == '\\') {
                escaping = true;
                continue;
            } else if (c == ' ') {
                if (!name.empty()) names.push_back(name);
                name.clear();
                continue;
            }
            name += c;
        }
        names.push_back(name);
        for (const std::string& candidate : names) {
            if (read.count(candidate)) break;
            std::string found = locate(candidate);
            if (!found.empty()) {
                read.insert(candidate);
                files.push_back(found);
                break;
            }
        }
    }
    return files;
}

std::vector<MtlColours> checkMtlText(std::string_view text, const std::string& where, const std::string& file) {
    const Source src{where, file};
    std::vector<MtlColours> materials;
    MtlColours current;
    LineReader reader(text);
    std::string_view line;
    std::vector<std::string_view> t;
    while (reader.next(line)) {
        const size_t n = reader.number();
        size_t i = 0;
        while (i < line.size() && isBlank(line[i])) ++i;
        if (i >= line.size() || line[i] == '#') continue;
        std::string_view rest = line.substr(i);
        if (rest.size() > 7 && rest.substr(0, 6) == "newmtl" && isBlank(rest[6])) {
            if (!current.name.empty()) materials.push_back(current);
            current = MtlColours{};
            std::string_view name = rest.substr(7);  // the rest of the line, as tinyobjloader takes it
            while (!name.empty() && isBlank(name.back())) name.remove_suffix(1);
            current.name = std::string(name);
            continue;
        }
        splitTokens(rest, t);
        const std::string_view key = t[0];
        if (key == "Kd" || key == "Ke") {  // the colours wedge renders
            if (t.size() > 1 && (t[1] == "spectral" || t[1] == "xyz"))
                fail(src, n, std::string(1, '`').append(key).append(" ").append(t[1]).append("` colours are not supported; give r g b"));
            expectNumbers(t, 1, 3, "r g b (or one number for grey)", src, n);
            if (t.size() == 3)
                fail(src, n, "`" + std::string(key) + "` expects r g b (or one number for grey), got 2 values");
            (key == "Kd" ? current.greyKd : current.greyKe) = t.size() == 2;  // the last statement counts
        } else if (key == "map_Kd" && t.size() > 1) {
            std::string_view args = rest.substr(6);
            while (!args.empty() && isBlank(args.front())) args.remove_prefix(1);
            while (!args.empty() && isBlank(args.back())) args.remove_suffix(1);
            current.mapKd = std::string(args);
        }
    }
    if (!current.name.empty()) materials.push_back(current);
    return materials;
}

}  // namespace wedge::scene
