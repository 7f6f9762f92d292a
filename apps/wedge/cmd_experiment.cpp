#include "apps/wedge/commands.h"

namespace wedge::app {

void registerExperiment(CLI::App&) {}

}  // namespace wedge::app
