// ChainTube — laying a hose along route points.
#pragma once

#include "chaintube/types.h"

#include <vector>

namespace chaintube {

/// Round the interior corners of a polyline with circular arcs of the given radius (metres,
/// ≥ 0). A corner's arc needs radius · tan(turn / 2) of each adjacent leg; where a leg is
/// shorter than what the corners at its two ends need, it is shared in proportion to their
/// needs (an end leg belongs to its one corner whole), and the corner gets a smaller arc
/// (tightCorners() lists those). Returns a dense polyline whose arcs are sampled with at most
/// maxArcStep (metres > 0) between samples. Consecutive duplicate points and exactly straight
/// corners are passed through; an exact reversal stays a sharp corner.
std::vector<Vec3> filletRoute(const std::vector<Vec3>& route, double radius, double maxArcStep);

/// A route corner that filletRoute() cannot round with the radius asked for.
struct TightCorner
{
    int routePoint = 0;         ///< index into the route as given
    double reachedRadius = 0.0; ///< the arc's radius there (metres; 0: an exact reversal)
    double turn = 0.0;          ///< the corner's turn (radians)
};

/// The corners of `route` whose legs are too short for arcs of `radius` (metres), as
/// filletRoute() shares them; empty when every corner gets its arc (or radius ≤ 0).
std::vector<TightCorner> tightCorners(const std::vector<Vec3>& route, double radius);

/// Points at equal arc-length spacing along a polyline: segments + 1 points, first and last
/// equal to the polyline's ends. segments ≥ 1; the polyline must have positive length.
std::vector<Vec3> resampleByArcLength(const std::vector<Vec3>& polyline, int segments);

/// Length of a polyline (metres).
double polylineLength(const std::vector<Vec3>& polyline);

} // namespace chaintube
