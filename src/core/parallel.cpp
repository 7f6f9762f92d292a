#include "core/parallel.h"

#include <tbb/info.h>
#include <tbb/task_arena.h>

namespace wedge {

ThreadLimit::ThreadLimit(int threads) {
    if (threads > 0)
        m_control = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(threads));
}

int ThreadLimit::current() {
    return int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
}

}  // namespace wedge
