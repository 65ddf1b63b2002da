// ChainTube — cutting a hose in two at an axis point (a damaged hose cut and replaced).
#pragma once

#include "chaintube/hose.h"

#include <vector>

namespace chaintube {

/// The two pieces of a hose cut at an axis point.
struct CutHose
{
    Hose before; ///< points 0 … point of the hose cut; its last point is a free end
    Hose after;  ///< points point … n; its first point is a free end
    /// Per attachment of the hose cut (in its attachments() order): the piece that holds it
    /// now (0 before, 1 after) and its id there.
    struct Moved
    {
        int piece = 0;
        int id = 0;
    };
    std::vector<Moved> attachments;
};

/// Cuts `hose` at axis point `point` (0 < point < pointCount() − 1): both pieces keep the
/// points, rest lengths, material, profile and options of their part (the cut point belongs to
/// both, so no length is lost), each attachment and clip goes with the piece it lies on (an
/// attachment at its current points, so an unmet one is met where the hose now is; a clip at
/// its place along the piece, its end stops clipped to the piece), and neither piece carries
/// the hose's motion, held point or torsion state (each starts as a new hose at rest).
/// Throws InvalidArgument naming the point when it is an end, out of range, fixed by an
/// attachment, or on a clip's segment.
CutHose cutHose(const Hose& hose, int point);

} // namespace chaintube
