// ChainTube — measures of a hose's state for tests, the editor's problems panel and export.
#pragma once

#include "chaintube/hose.h"

#include <vector>

namespace chaintube {

struct HoseMetrics
{
    /// Largest and smallest segment length relative to rest length (1 = rest).
    double maxStretch = 1.0;
    double minStretch = 1.0;
    /// Largest excess beyond the stretch band, relative to rest length (0 = within band).
    double lengthViolation = 0.0;
    int lengthViolationSegment = -1;
    /// Largest excess of a joint's turn beyond its deflection limit (radians).
    double angleViolation = 0.0;
    int angleViolationJoint = -1;
    /// Smallest bend radius present (metres, from the turn angle and the mean adjacent current
    /// segment length); the largest finite double for a straight hose.
    double smallestBendRadius = 0.0;
    int smallestBendRadiusJoint = -1;
    /// Joints whose bend radius is below the material's minimum bend radius (by more than
    /// 1e-9 relative). Empty for a DeflectionAngle material (use angleViolation).
    std::vector<int> bendBelowMinimum;
    /// Ring self-intersection on the inside of bends: per segment s, the ratio
    /// r·(tan(φ_s/2) + tan(φ_{s+1}/2)) / l_s of how far the two rings' inner edges reach along
    /// the segment to its length (r = profile bounding radius, φ = turn at each end); > 1 means
    /// the rings cross. Exact for rings bending to the same side, conservative otherwise.
    double worstRingOverlap = 0.0;
    int worstRingOverlapSegment = -1;
    std::vector<int> selfIntersectingSegments;

    /// Attachments whose frame is beyond the hose's reach: id and gap (metres, see
    /// Hose::attachmentGap), for gaps above 1e-9 m.
    struct UnmetAttachment
    {
        int id = 0;
        double gap = 0.0;
    };
    std::vector<UnmetAttachment> unmetAttachments;

    bool overstretched() const { return lengthViolation > 1e-9; }
    bool hasProblems() const
    {
        return overstretched() || angleViolation > 1e-9 || !bendBelowMinimum.empty() ||
               !selfIntersectingSegments.empty() || !unmetAttachments.empty();
    }
};

/// Measures the hose's current shape against its material and attachments. O(points); never
/// throws; every value finite.
HoseMetrics measure(const Hose& hose);

} // namespace chaintube
