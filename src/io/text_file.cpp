#include "io/text_file.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"

namespace wedge::io {

std::string notARegularFile(const std::string& path) {
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (status.type() == std::filesystem::file_type::not_found) return "no such file";
    if (ec) return ec.message();
    if (status.type() == std::filesystem::file_type::directory) return "is a directory";
    if (status.type() != std::filesystem::file_type::regular) return "not a regular file";
    return "";
}

std::string readTextFile(const std::string& file) {
    if (const std::string why = notARegularFile(file); !why.empty()) throw Error(file, why);
    std::ifstream in(file, std::ios::binary);
    if (!in) throw Error(file, "cannot open for reading");
    std::ostringstream text;
    text << in.rdbuf();
    if (in.bad()) throw Error(file, "cannot read");
    return text.str();
}

std::string htmlEscape(const std::string& s) {
    std::string out;
    for (char c : s) {
        if (c == '<') out += "&lt;";
        else if (c == '>') out += "&gt;";
        else if (c == '&') out += "&amp;";
        else if (c == '"') out += "&quot;";
        else out += c;
    }
    return out;
}

}  // namespace wedge::io
