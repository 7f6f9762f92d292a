#include "apps/wedge/commands.h"

namespace wedge::app {

void registerRaster(CLI::App&) {}

}  // namespace wedge::app
