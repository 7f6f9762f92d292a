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

}  // namespace wedge::io
