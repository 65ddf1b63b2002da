// Test helpers shared by the test folders that measure hoses built by the library.
#pragma once

#include "chaintube/hose.h"

#include <algorithm>

namespace chaintube::test_support {

/// Largest relative excess of a segment beyond its stretch band [minLength, maxLength] (0: every
/// segment in it), measured from the points.
inline double worstBandExcess(const Hose& hose)
{
    double worst = 0.0;
    for (int s = 0; s < hose.segmentCount(); ++s) {
        const double length = (hose.point(s + 1) - hose.point(s)).norm();
        worst = std::max({worst, (length - hose.maxLength(s)) / hose.restLength(s),
                          (hose.minLength(s) - length) / hose.restLength(s)});
    }
    return worst;
}

} // namespace chaintube::test_support
