#include "apps/wedge/commands.h"

namespace wedge::app {

void registerAnalyze(CLI::App&) {}

}  // namespace wedge::app
