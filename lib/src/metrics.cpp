#include "chaintube/metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace chaintube {

HoseMetrics measure(const Hose& hose)
{
    HoseMetrics m;
    const std::vector<Vec3>& p = hose.localPoints();
    const int n = hose.pointCount();
    std::vector<double> length(static_cast<size_t>(n - 1));
    for (int s = 0; s + 1 < n; ++s) {
        length[static_cast<size_t>(s)] =
            (p[static_cast<size_t>(s + 1)] - p[static_cast<size_t>(s)]).norm();
        const double stretch = length[static_cast<size_t>(s)] / hose.restLength(s);
        m.maxStretch = s == 0 ? stretch : std::max(m.maxStretch, stretch);
        m.minStretch = s == 0 ? stretch : std::min(m.minStretch, stretch);
        const double excess = std::max(length[static_cast<size_t>(s)] - hose.maxLength(s),
                                       hose.minLength(s) - length[static_cast<size_t>(s)]) /
                              hose.restLength(s);
        if (excess > m.lengthViolation) {
            m.lengthViolation = excess;
            m.lengthViolationSegment = s;
        }
    }
    std::vector<double> halfTurnTan(static_cast<size_t>(n), 0.0);
    m.smallestBendRadius = std::numeric_limits<double>::max();
    const BendLimit& limit = hose.material().bendLimit;
    const bool radiusLimited = limit.kind == BendLimit::Kind::MinBendRadius && limit.value > 0.0;
    for (int j = 1; j + 1 < n; ++j) {
        const Vec3 in = p[static_cast<size_t>(j)] - p[static_cast<size_t>(j - 1)];
        const Vec3 out = p[static_cast<size_t>(j + 1)] - p[static_cast<size_t>(j)];
        const double turn = std::atan2(in.cross(out).norm(), in.dot(out));
        const double excess = turn - hose.deflectionLimit(j);
        if (excess > m.angleViolation) {
            m.angleViolation = excess;
            m.angleViolationJoint = j;
        }
        const double meanLength =
            0.5 * (length[static_cast<size_t>(j - 1)] + length[static_cast<size_t>(j)]);
        const double radius = bendRadiusOfTurn(meanLength, turn);
        if (radius < m.smallestBendRadius) {
            m.smallestBendRadius = radius;
            m.smallestBendRadiusJoint = j;
        }
        if (radiusLimited && radius < limit.value * (1.0 - 1e-9)) m.bendBelowMinimum.push_back(j);
        halfTurnTan[static_cast<size_t>(j)] =
            std::min(std::tan(0.5 * std::min(turn, 3.14159)), 1e12);
    }
    const double radius = hose.profile().boundingRadius();
    for (int s = 0; s + 1 < n; ++s) {
        const double reach = radius * (halfTurnTan[static_cast<size_t>(s)] +
                                       halfTurnTan[static_cast<size_t>(s + 1)]);
        const double ratio = reach / length[static_cast<size_t>(s)];
        if (ratio > m.worstRingOverlap) {
            m.worstRingOverlap = ratio;
            m.worstRingOverlapSegment = s;
        }
        if (ratio > 1.0) m.selfIntersectingSegments.push_back(s);
    }
    for (const Hose::Attachment& a : hose.attachments()) {
        const double gap = hose.attachmentGap(a.id);
        if (gap > 1e-9) m.unmetAttachments.push_back({a.id, gap});
    }
    return m;
}

} // namespace chaintube
