// The update entry points that end with the contact step: Hose::grab and one attachment move
// (moveAttachmentsOnce, under budget.cpp's moveAttachments). Each is the solver's update
// without colliders (solver.cpp) followed by Hose::applyCollisions (hose_contact.cpp), so the
// calls go one way: update → contact → solver.
#include "budget.h"
#include "chaintube/hose.h"

namespace chaintube {

UpdateResult Hose::grab(int index, const Vec3& target)
{
    if (!grabAccepts(index, target)) {
        UpdateResult result;
        result.status = Status::InvalidInput;
        return result;
    }
    BudgetScope scope(*this);
    GrabSolve solve = solveGrab(index, target);
    if (solve.answered) return solve.result;
    if (!m_colliders.empty()) applyCollisions(solve.result, index, target - m_origin);
    return finishGrab(index, target, solve, scope.cut());
}

UpdateResult Hose::moveAttachmentsOnce(const std::vector<int>& ids,
                                       const std::vector<Frame>& frames)
{
    UpdateResult result = solveAttachmentMove(ids, frames);
    if (result.status != Status::InvalidInput && !m_colliders.empty())
        applyCollisions(result, -1, Vec3::Zero());
    return result;
}

} // namespace chaintube
