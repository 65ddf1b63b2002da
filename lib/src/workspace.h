// A hose's scratch buffers (Hose::m_workspace): the vectors of the chain projection, the span
// solver and the gravity step, kept between updates so that a frame does not allocate them
// again. Each user takes its buffers for its lifetime and gives them back (a second user made
// meanwhile starts with its own); none of it is the hose's state. Internal to lib/.
#pragma once

#include "projection.h"
#include "span_solver.h"

#include <vector>

namespace chaintube::detail {

struct Workspace
{
    ProjectionBuffers projection;
    SpanBuffers span;
    std::vector<Vec3> gravityStart, gravityPredicted; ///< Hose::step
};

} // namespace chaintube::detail
