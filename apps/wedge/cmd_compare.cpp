#include "apps/wedge/commands.h"

namespace wedge::app {

void registerCompare(CLI::App&) {}

}  // namespace wedge::app
