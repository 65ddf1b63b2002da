#include "chaintube/types.h"

namespace chaintube {

bool isFiniteFrame(const Frame& frame)
{
    return frame.rotation.coeffs().allFinite() && frame.translation.allFinite() &&
           std::abs(frame.rotation.norm() - 1.0) < 1e-6;
}

} // namespace chaintube
