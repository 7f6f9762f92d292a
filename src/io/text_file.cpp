#include "io/text_file.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"

namespace wedge::io {

std::string readTextFile(const std::string& file) {
    if (!std::filesystem::exists(file)) throw Error(file, "no such file");
    if (std::filesystem::is_directory(file)) throw Error(file, "is a directory");
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
