// ChainTube — laying a hose along route points.
#pragma once

#include "chaintube/types.h"

#include <vector>

namespace chaintube {

/// Round the interior corners of a polyline with circular arcs of the given radius (metres,
/// ≥ 0), each limited so it uses at most half of either adjacent leg. Returns a dense polyline
/// whose arcs are sampled with at most maxArcStep (metres > 0) between samples.
/// Consecutive duplicate points and exactly straight corners are passed through.
std::vector<Vec3> filletRoute(const std::vector<Vec3>& route, double radius, double maxArcStep);

/// Points at equal arc-length spacing along a polyline: segments + 1 points, first and last
/// equal to the polyline's ends. segments ≥ 1; the polyline must have positive length.
std::vector<Vec3> resampleByArcLength(const std::vector<Vec3>& polyline, int segments);

/// Length of a polyline (metres).
double polylineLength(const std::vector<Vec3>& polyline);

} // namespace chaintube
