// An update larger than one solve: an attachment move made again in halves when it finds no
// shape, and under a budget (Hose::setBudget) the work left pending and its continuation in
// the next updates (Hose::step() calls continuePending()).
#include "budget.h"

#include "chaintube/hose.h"

#include <algorithm>
#include <optional>
#include <string>
#include <utility>

namespace chaintube {

namespace {

/// Hose::moveAttachments: a move that finds no shape is made again in two halves when an
/// attachment moves by more than this many (first) segment lengths, at most this many times
/// halved (at most 2 + 4 + … more updates).
constexpr double kHalvedMove = 2.0;
constexpr int kMoveHalvings = 2;

} // namespace

UpdateResult Hose::moveAttachments(const std::vector<int>& ids, const std::vector<Frame>& frames)
{
    BudgetScope scope(*this);
    m_updatedSinceStep = true;
    // Under a budget the move is not halved: the budget's own partial moves go on next frame,
    // and a move that is pending goes on with this one (the attachments it has not yet met, at
    // their frames).
    if (scope.bounded() && m_pendingMove && ids.size() == frames.size()) {
        std::vector<int> allIds = ids;
        std::vector<Frame> allFrames = frames;
        for (const Attachment& a : m_attachments)
            if (std::find(ids.begin(), ids.end(), a.id) == ids.end() && attachmentGap(a.id) > 0.0) {
                allIds.push_back(a.id);
                allFrames.push_back(a.frame);
            }
        if (allIds.size() > ids.size()) {
            UpdateResult result = moveAttachmentsInSteps(allIds, allFrames, 0);
            m_pendingMove = result.pending;
            return result;
        }
    }
    UpdateResult result = moveAttachmentsInSteps(ids, frames, scope.bounded() ? 0 : kMoveHalvings);
    m_pendingMove = result.pending;
    return result;
}

void Hose::setBudget(const UpdateBudget& budget)
{
    if (budget.newtonSteps < 0)
        throw InvalidArgument("budget.newtonSteps: expected a number of steps >= 0 (0: no bound), "
                              "got " +
                              std::to_string(budget.newtonSteps));
    m_budget = budget;
}

double Hose::remaining() const
{
    double remaining = m_pendingGrab ? m_pendingGrabRemaining : 0.0;
    if (m_pendingMove)
        for (const Attachment& a : m_attachments)
            remaining = std::max(remaining, attachmentGap(a.id));
    return remaining;
}

UpdateResult Hose::finishPending()
{
    BudgetScope unbounded(*this, false);
    return continuePending();
}

UpdateResult Hose::continuePending()
{
    UpdateResult result;
    if (m_pendingGrab && m_held >= 0 && !m_fixed[static_cast<size_t>(m_held)])
        result = grab(m_held, m_pendingGrabTarget);
    m_pendingGrab = result.pending;
    if (!m_pendingMove) return result;
    std::vector<int> ids;
    std::vector<Frame> frames;
    for (const Attachment& a : m_attachments)
        if (attachmentGap(a.id) > 0.0) {
            ids.push_back(a.id);
            frames.push_back(a.frame);
        }
    if (ids.empty()) {
        m_pendingMove = false;
        return result;
    }
    const UpdateResult move = moveAttachments(ids, frames);
    if (result.iterations == 0 && result.movedPoints == 0 && !result.pending) return move;
    UpdateResult both = move;
    both.status = std::max(result.status, move.status);
    both.grabError = result.grabError;
    both.movedPoints = std::max(result.movedPoints, move.movedPoints);
    both.iterations += result.iterations;
    both.pending = result.pending || move.pending;
    both.remaining = std::max(result.remaining, move.remaining);
    return both;
}

UpdateResult Hose::moveAttachmentsInSteps(const std::vector<int>& ids,
                                          const std::vector<Frame>& frames, int halvings)
{
    // Where each attachment is before the move (an unknown id: the single update refuses it).
    std::vector<Frame> from;
    double longest = 0.0;
    for (size_t i = 0; i < ids.size() && i < frames.size(); ++i)
        if (const Attachment* a = attachmentWithId(ids[i])) {
            from.push_back(a->frame);
            const Vec3 local = a->isClip() ? a->clipCentre : a->localPoints.front();
            longest = std::max(longest, (frames[i].apply(local) - a->frame.apply(local)).norm());
        }
    const bool wasValid = !m_dirtyViolation;
    // A long move of a valid hose may be made again in halves from the hose as it is now.
    const bool mayHalve = halvings > 0 && wasValid && from.size() == ids.size() &&
                          longest > kHalvedMove * m_restLength.front();
    std::optional<Hose> before;
    if (mayHalve) before = *this;
    UpdateResult result = moveAttachmentsOnce(ids, frames);
    // No valid shape found (the hose stayed where it was, or its bends gave way) for a long
    // move of a valid hose: the move again as two halves from where the hose is, kept only when
    // both find a valid shape.
    if (!mayHalve || result.status != Status::Infeasible ||
        (result.movedPoints != 0 && !(result.angleViolation > 0.0)))
        return result;
    const Hose unmet = *this;
    *this = std::move(*before); // back where it was before the move
    const std::vector<Vec3> start = m_local;
    std::vector<Frame> halfway(frames.size());
    for (size_t i = 0; i < frames.size(); ++i) {
        halfway[i].rotation = from[i].rotation.slerp(0.5, frames[i].rotation);
        halfway[i].translation = 0.5 * (from[i].translation + frames[i].translation);
    }
    const UpdateResult first = moveAttachmentsInSteps(ids, halfway, halvings - 1);
    if (first.status == Status::Ok) {
        UpdateResult second = moveAttachmentsInSteps(ids, frames, halvings - 1);
        if (second.status == Status::Ok) {
            second.iterations += first.iterations + result.iterations;
            second.movedPoints = 0;
            for (size_t i = 0; i < m_local.size(); ++i)
                second.movedPoints += m_local[i] != start[i];
            return second;
        }
    }
    const int iterations = result.iterations;
    *this = unmet;
    result.iterations = iterations + first.iterations;
    return result;
}

} // namespace chaintube
