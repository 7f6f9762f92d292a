// The one exception type for bad input (scene files, meshes, flags, images). It carries a
// location prefix such as "room.json: objects[3].radius" so that the message names the file
// and the field. Only main() catches it, prints it and exits with code 2 (Falcor's rule:
// programmer mistakes are assertions, bad input is an exception, catch only at the top).
#pragma once

#include <stdexcept>
#include <string>

namespace wedge {

class Error : public std::runtime_error {
public:
    explicit Error(const std::string& message) : std::runtime_error(message) {}
    /// "where: what", e.g. Error("room.json: objects[3].radius", "expected a positive number").
    Error(const std::string& where, const std::string& what) : std::runtime_error(where + ": " + what) {}
};

}  // namespace wedge
