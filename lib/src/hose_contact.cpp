// A hose staying outside its colliders: Hose::setColliders, resolveCollisions and
// applyCollisions, the contact step every grab, attachment move and gravity step ends with
// (update.cpp, sag.cpp). It calls into the solver (solver.cpp: grabs made again without
// colliders, closeSpans), never back into an update. The colliders' geometry and queries are
// in mesh_collider.cpp.
#include "budget.h"
#include "chaintube/collision.h"
#include "chaintube/hose.h"
#include "projection.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace chaintube {

namespace {

/// Hose::applyCollisions: Newton steps of the chain projection with the contacts, and the
/// largest violation it stops at (relative length, radians, contact depth over a segment), from
/// which the span solver closes the rest exactly (Hose::closeSpans): its moves are of the order
/// of the violation.
constexpr int kContactProjectionSteps = 8;
constexpr double kContactProjectionClose = 1e-5;
/// Hose::applyCollisions: Newton steps restoring the lengths and bends of the contact rounds'
/// shape without the contacts, when a moved collider leaves no other shape to keep.
constexpr int kRepairProjectionSteps = 32;
/// A clearance bound not yet known (applyCollisions' per-point bounds).
constexpr double kUnknownClearance = -std::numeric_limits<double>::infinity();
/// Segments are swept (MeshCollider::sweepSegment) keeping their axis this fraction of the
/// outer radius from the colliders: the pushing out then sees on which side the segment is
/// and moves it out there (an axis touching a thin plate or an edge would have no side).
constexpr double kSegmentGuard = 0.5;
/// Passes over the hose of the segments' sweep from the previous shape (each segment stopped
/// moves its ends, so its neighbours are swept again on the next pass).
constexpr int kSegmentPasses = 3;
/// Hose::applyCollisions: a grab whose move would bring a segment's axis within the guard of a
/// collider, or leave a constraint off, is made again towards 1/2, 1/4, … of the way to where its
/// point may go, at most this many times, before the previous shape is kept.
constexpr int kGrabFallbacks = 3;

} // namespace

// --- Hose: staying outside the colliders ----------------------------------------------------

void Hose::setColliders(std::vector<std::shared_ptr<const MeshCollider>> colliders,
                        const CollisionOptions& options)
{
    for (std::size_t i = 0; i < colliders.size(); ++i)
        if (!colliders[i])
            throw InvalidArgument("colliders[" + std::to_string(i) +
                                  "]: expected a collider, got null");
    if (!(options.tolerance > 0.0) || !std::isfinite(options.tolerance))
        throw InvalidArgument("collision tolerance: expected a finite value > 0 metres");
    if (!(options.constraintTolerance > 0.0) || !std::isfinite(options.constraintTolerance))
        throw InvalidArgument("collision constraintTolerance: expected a finite value > 0");
    if (options.maxRounds < 1) throw InvalidArgument("collision maxRounds: expected ≥ 1");
    m_colliders = std::move(colliders);
    m_collisionOptions = options;
    m_collisionStart.clear();
    m_collisionFree.clear();
    m_colliderFrames.clear();
    for (const auto& c : m_colliders)
        m_colliderFrames.push_back(c->frame());
    if (!m_colliders.empty()) m_collisionStart = m_local;
    m_collisionRevision = m_revision;
    m_edgePoint = -1; // grab(): what was the edge of reach may no longer be
}

UpdateResult Hose::resolveCollisions()
{
    BudgetScope scope(*this);
    UpdateResult result = measureViolation();
    result.status = Status::Ok;
    if (m_colliders.empty()) return result;
    if (m_collisionStart.size() != m_local.size()) m_collisionStart = m_local;
    applyCollisions(result, -1, Vec3::Zero());
    return result;
}

namespace {

bool sameFrame(const Frame& a, const Frame& b)
{
    return a.translation == b.translation && a.rotation.coeffs() == b.rotation.coeffs();
}

/// The colliders near one hose update, queried in world coordinates. A collider that moved
/// since the last update carries the relative motion new ∘ old⁻¹: a sweep that starts from the
/// hose's previous shape starts from where that shape sat relative to the collider, so a
/// moving collider pushes the hose instead of jumping over it.
class ContactSet
{
public:
    ContactSet(const std::vector<std::shared_ptr<const MeshCollider>>& all,
               const std::vector<Frame>& previousFrames, const Aabb& region)
    {
        for (std::size_t c = 0; c < all.size(); ++c) {
            const MeshCollider& collider = *all[c];
            Entry entry{&collider, Frame::identity(), false};
            if (c < previousFrames.size() && !sameFrame(previousFrames[c], collider.frame())) {
                entry.relative = collider.frame() * previousFrames[c].inverse();
                entry.moved = true;
            }
            // A collider that moved is always checked (its relative sweep starts elsewhere).
            if (entry.moved || collider.worldBounds().overlaps(region)) m_near.push_back(entry);
        }
    }
    bool empty() const { return m_near.empty(); }

    struct Hit
    {
        MeshCollider::Sweep sweep;
        Vec3 start = Vec3::Zero(); ///< where the sweep began for the collider that was hit
    };
    /// First contact of a sphere moving from `from` to `to`; with relativeStart, `from` is a
    /// position of the previous update (see the class comment).
    Hit sweep(const Vec3& from, const Vec3& to, double radius, bool relativeStart) const
    {
        Hit best;
        for (const Entry& e : m_near) {
            const Vec3 start = relativeStart && e.moved ? e.relative.apply(from) : from;
            const MeshCollider::Sweep s = e.collider->sweepSphere(start, to, radius);
            if (s.hit && (!best.sweep.hit || s.fraction < best.sweep.fraction)) {
                best.sweep = s;
                best.start = start;
            }
        }
        return best;
    }
    struct SegmentHit
    {
        MeshCollider::SegmentSweep sweep;
        Vec3 startA = Vec3::Zero(), startB = Vec3::Zero(); ///< as for Hit::start
    };
    /// First contact of the segment whose ends move from a0, b0 to a1, b1, its axis kept
    /// `guard` from every collider; with relativeStart, a0 and b0 are of the previous update.
    SegmentHit sweepSegment(const Vec3& a0, const Vec3& b0, const Vec3& a1, const Vec3& b1,
                            double guard, bool relativeStart) const
    {
        SegmentHit best;
        for (const Entry& e : m_near) {
            const bool relative = relativeStart && e.moved;
            const Vec3 startA = relative ? e.relative.apply(a0) : a0;
            const Vec3 startB = relative ? e.relative.apply(b0) : b0;
            const MeshCollider::SegmentSweep s =
                e.collider->sweepSegment(startA, startB, a1, b1, guard);
            if (s.hit && (!best.sweep.hit || s.fraction < best.sweep.fraction)) {
                best.sweep = s;
                best.startA = startA;
                best.startB = startB;
            }
        }
        return best;
    }
    MeshCollider::Closest closestToPoint(const Vec3& p, double maxDistance) const
    {
        MeshCollider::Closest best;
        for (const Entry& e : m_near) {
            const MeshCollider::Closest q =
                e.collider->closestToPoint(p, best.found ? best.distance : maxDistance);
            if (q.found && (!best.found || q.distance < best.distance)) best = q;
        }
        return best;
    }
    MeshCollider::Closest closestToSegment(const Vec3& a, const Vec3& b, double maxDistance) const
    {
        MeshCollider::Closest best;
        for (const Entry& e : m_near) {
            const MeshCollider::Closest q =
                e.collider->closestToSegment(a, b, best.found ? best.distance : maxDistance);
            if (q.found && (!best.found || q.distance < best.distance)) best = q;
        }
        return best;
    }

private:
    struct Entry
    {
        const MeshCollider* collider;
        Frame relative;
        bool moved;
    };
    std::vector<Entry> m_near;
};

} // namespace

void Hose::applyCollisions(UpdateResult& result, int grabbed, const Vec3& localTarget)
{
    if (m_colliders.empty()) return;
    const std::size_t n = m_local.size();
    const double radius = outerRadius();
    const double tolerance = m_collisionOptions.tolerance;
    // The previous shape is exactly the one before this update when only this update changed
    // the revision; a grab can then be redone from it (below).
    const bool startIsPrevious =
        m_collisionStart.size() == n && m_revision == m_collisionRevision + 1;
    if (m_collisionStart.size() != n) m_collisionStart = m_local;

    // Per-point lower bounds on the clearance (axis distance − radius) stay valid while no
    // collider moved; a point that moved less than its bound cannot have touched anything.
    bool collidersMoved =
        m_colliderFrames.size() != m_colliders.size() || m_collisionFree.size() != n;
    for (std::size_t c = 0; !collidersMoved && c < m_colliders.size(); ++c)
        collidersMoved = !sameFrame(m_colliderFrames[c], m_colliders[c]->frame());
    if (collidersMoved)
        m_collisionFree.assign(n, kUnknownClearance); // unknown: query before trusting
    // A collider's frame changed since the last update: its relative motion is what the
    // segments are kept from (every later point move sweeps its two segments; the contacts'
    // projection holds edges between points; the previous shape is kept only if clear).
    bool frameMoved = false;
    for (std::size_t c = 0; !frameMoved && c < m_colliders.size() && c < m_colliderFrames.size();
         ++c)
        frameMoved = !sameFrame(m_colliderFrames[c], m_colliders[c]->frame());
    auto finish = [&]() {
        m_collisionStart = m_local;
        m_colliderFrames.clear();
        for (const auto& c : m_colliders)
            m_colliderFrames.push_back(c->frame());
        m_collisionRevision = m_revision;
    };

    Aabb region;
    for (std::size_t i = 0; i < n; ++i) {
        region.extend(m_collisionStart[i] + m_origin);
        region.extend(m_local[i] + m_origin);
    }
    double maxRest = 0.0;
    for (double l : m_restLength)
        maxRest = std::max(maxRest, l);
    const double margin = radius + tolerance + maxRest;
    region.min.array() -= margin;
    region.max.array() += margin;
    const ContactSet contacts(m_colliders, m_colliderFrames, region);
    if (contacts.empty()) {
        m_collisionFree.assign(n, margin - radius); // no collider within margin of any point
        finish();
        return;
    }
    const double queryReach = radius + 2.0 * maxRest + 0.05; // bound on one clearance query

    std::vector<double>& freeBound = m_collisionFree;
    std::vector<unsigned char> pinned(m_fixed.begin(), m_fixed.end());
    if (grabbed >= 0) pinned[static_cast<std::size_t>(grabbed)] = 1;
    const double guard = kSegmentGuard * radius;

    // Point i moving from `from` to `to` (local) with its neighbours where they are: the
    // segments on either side sweep triangles, and stop the move where one would come within
    // `guard` of a collider (a thin plate or an edge between two axis points). Returns where the
    // point may go. Skipped where the neighbour's clearance bound excludes any contact.
    auto keepSegments = [&](std::size_t i, const Vec3& from, Vec3 to) {
        if (!frameMoved) return to;
        for (const std::size_t j : {i - 1, i + 1}) {
            if (j >= n) continue; // i − 1 of point 0 wraps round
            const Vec3& other = m_local[j];
            const double span = std::max((from - other).norm(), (to - other).norm());
            if (freeBound[j] + radius - span > guard) continue;
            const ContactSet::SegmentHit h = contacts.sweepSegment(
                other + m_origin, from + m_origin, other + m_origin, to + m_origin, guard, false);
            if (h.sweep.hit) to = from + h.sweep.fraction * (to - from);
        }
        return to;
    };

    // Moves point i from `from` to `to` (local), stopping at first contact and sliding along
    // it (at most three contacts per move). Keeps freeBound[i] a lower bound.
    auto moveSwept = [&](std::size_t i, const Vec3& from, const Vec3& to, bool relativeStart) {
        const double length = (to - from).norm();
        if (freeBound[i] > length) {
            freeBound[i] -= length;
            return relativeStart ? to : keepSegments(i, from, to);
        }
        Vec3 position = from + m_origin;
        const Vec3 goal = to + m_origin;
        bool touched = false;
        for (int slide = 0; slide < 3; ++slide) {
            if ((goal - position).norm() <= 1e-15 && !(relativeStart && slide == 0)) break;
            const ContactSet::Hit h =
                contacts.sweep(position, goal, radius, relativeStart && slide == 0);
            if (!h.sweep.hit) {
                position = goal;
                break;
            }
            touched = true;
            const Vec3 contact =
                h.start + h.sweep.fraction * (goal - h.start) + 1e-9 * h.sweep.normal;
            Vec3 rest = goal - contact;
            const double into = rest.dot(h.sweep.normal);
            if (into < 0.0) rest -= into * h.sweep.normal;
            position = contact;
            if (slide == 2) break;
            // Slide: the remaining move without its part into the surface.
            const Vec3 slideGoal = contact + rest;
            const ContactSet::Hit s2 = contacts.sweep(position, slideGoal, radius, false);
            if (!s2.sweep.hit) {
                position = slideGoal;
                break;
            }
            position =
                s2.start + s2.sweep.fraction * (slideGoal - s2.start) + 1e-9 * s2.sweep.normal;
            break;
        }
        freeBound[i] = touched ? 0.0 : freeBound[i] - length;
        const Vec3 reached = position - m_origin;
        return relativeStart ? reached : keepSegments(i, from, reached);
    };

    std::vector<Vec3> solved = m_local; // where the collision-free solver put the points
    bool changed = false;
    // Where the grabbed point may go: the solver's place for it, stopped at first contact.
    Vec3 grabReach = grabbed >= 0 ? solved[static_cast<std::size_t>(grabbed)] : Vec3::Zero();

    // A grabbed point stopped by a collider: redo the grab from the previous shape towards
    // where the point can go, so the rest of the hose follows it with the exact ChainTube
    // propagation instead of being pushed into the obstacle after it.
    if (grabbed >= 0 && startIsPrevious) {
        const std::size_t k = static_cast<std::size_t>(grabbed);
        const Vec3 reach = moveSwept(k, m_collisionStart[k], solved[k], true);
        grabReach = reach;
        if ((reach - solved[k]).squaredNorm() > 1e-24) {
            std::vector<std::shared_ptr<const MeshCollider>> colliders;
            colliders.swap(m_colliders); // the redo is a grab without colliders
            m_local = m_collisionStart;
            const UpdateResult redo = grabWithoutContacts(grabbed, reach + m_origin);
            m_colliders.swap(colliders);
            result.status = redo.status;
            result.lengthViolation = redo.lengthViolation;
            result.angleViolation = redo.angleViolation;
            result.movedPoints = redo.movedPoints;
            result.iterations += redo.iterations;
            solved = m_local;
            changed = true;
        }
        freeBound[k] = kUnknownClearance;
    }

    // Every point travels from its last collision-free place to where the solver put it;
    // fixed points are where their frames put them.
    m_local = m_collisionStart;
    for (std::size_t i = 0; i < n; ++i) {
        if (m_fixed[i]) {
            freeBound[i] -= (solved[i] - m_local[i]).norm();
            m_local[i] = solved[i];
            continue;
        }
        m_local[i] = moveSwept(i, m_local[i], solved[i], true);
        changed |= (m_local[i] - solved[i]).squaredNorm() > 1e-24;
    }

    // Segments, not only points: each segment moves from where the previous shape had it
    // (relative to each moved collider) to where its points went, and stops short of the first
    // contact (kSegmentGuard): a thin plate or a knife edge passing between two axis points
    // pushes the segment along instead of crossing it. Its free ends go back along their own
    // moves; a stopped segment's neighbours are swept again on the next pass.
    for (int pass = 0; pass < kSegmentPasses; ++pass) {
        bool stopped = false;
        for (std::size_t s = 0; s + 1 < n; ++s) {
            if (m_fixed[s] && m_fixed[s + 1]) continue;
            const Vec3 &a0 = m_collisionStart[s], &b0 = m_collisionStart[s + 1];
            const Vec3 &a1 = m_local[s], &b1 = m_local[s + 1];
            // Without a moved collider the bound at a1 excludes a swept quad within its reach.
            const double span = std::max({(a0 - a1).norm(), (b0 - a1).norm(), (b1 - a1).norm()});
            if (!collidersMoved && freeBound[s] + radius - span > guard) continue;
            const ContactSet::SegmentHit h = contacts.sweepSegment(
                a0 + m_origin, b0 + m_origin, a1 + m_origin, b1 + m_origin, guard, true);
            if (!h.sweep.hit) continue;
            const double t = h.sweep.fraction;
            const Vec3 startOf[2] = {h.startA, h.startB};
            for (std::size_t k = 0; k < 2; ++k) {
                const std::size_t i = s + k;
                if (m_fixed[i]) continue;
                const Vec3 end = m_local[i] + m_origin;
                m_local[i] = startOf[k] + t * (end - startOf[k]) - m_origin;
                freeBound[i] = kUnknownClearance;
            }
            stopped = true;
            changed = true;
        }
        if (!stopped) break;
    }

    // Exact clearance where the bound does not exclude contact.
    auto pointClearance = [&](std::size_t i, MeshCollider::Closest* closest) {
        if (freeBound[i] >= tolerance) return freeBound[i];
        const MeshCollider::Closest c = contacts.closestToPoint(m_local[i] + m_origin, queryReach);
        freeBound[i] = c.found ? c.distance - radius : queryReach - radius;
        if (closest) *closest = c;
        return freeBound[i];
    };
    // Pushes penetrating points and segments out (with `move`; otherwise only measures);
    // returns the deepest penetration found.
    auto pushOut = [&](bool move = true) {
        double deepest = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            MeshCollider::Closest c;
            const double free = pointClearance(i, &c);
            if (free >= -tolerance || !c.found) continue;
            deepest = std::max(deepest, -free);
            if (pinned[i] || !move) continue;
            Vec3 normal = c.normal;
            if (c.distance < 1e-12) { // centre on the surface: go back to the side it came from
                const Vec3 back = m_collisionStart[i] + m_origin - c.onMesh;
                if (back.dot(normal) < 0.0) normal = -normal;
            }
            m_local[i] = moveSwept(i, m_local[i], m_local[i] + normal * (-free), false);
            changed = true;
        }
        for (std::size_t s = 0; s + 1 < n; ++s) {
            const double length = (m_local[s + 1] - m_local[s]).norm();
            if (std::min(freeBound[s], freeBound[s + 1]) >= 0.5 * length + tolerance) continue;
            const MeshCollider::Closest c = contacts.closestToSegment(
                m_local[s] + m_origin, m_local[s + 1] + m_origin, radius - tolerance);
            if (!c.found || c.distance >= radius - tolerance) continue;
            const double depth = radius - c.distance;
            deepest = std::max(deepest, depth);
            if (!move) continue;
            Vec3 normal = c.normal;
            if (c.distance < 1e-12) {
                const Vec3 mid = 0.5 * (m_collisionStart[s] + m_collisionStart[s + 1]) + m_origin;
                if ((mid - c.onMesh).dot(normal) < 0.0) normal = -normal;
            }
            const double t = c.segmentParameter;
            const double wa = pinned[s] ? 0.0 : 1.0 - t, wb = pinned[s + 1] ? 0.0 : t;
            const double norm = wa * wa + wb * wb;
            if (!(norm > 1e-6)) continue;
            if (wa > 0.0)
                m_local[s] =
                    moveSwept(s, m_local[s], m_local[s] + normal * (depth * wa / norm), false);
            if (wb > 0.0)
                m_local[s + 1] = moveSwept(s + 1, m_local[s + 1],
                                           m_local[s + 1] + normal * (depth * wb / norm), false);
            changed = true;
        }
        return deepest;
    };

    // Places point i against its neighbour j = i ∓ 1: within the length band of their segment
    // and within the deflection limit at j (turn from the segment before j). Swept.
    auto project = [&](std::size_t i, std::size_t j) {
        const std::size_t segment = std::min(i, j);
        const Vec3 d = m_local[i] - m_local[j];
        double length = d.norm();
        Vec3 direction = Vec3::UnitX();
        if (length > 1e-12 * m_restLength[segment]) {
            direction = d / length;
        } else { // on top of each other: towards i's other neighbour, else the previous shape
            const long k = static_cast<long>(i) + (static_cast<long>(i) - static_cast<long>(j));
            Vec3 fallback = m_collisionStart[i] - m_collisionStart[j];
            if (k >= 0 && k < static_cast<long>(n))
                fallback = m_local[static_cast<std::size_t>(k)] - m_local[j];
            if (fallback.norm() > 0.0) direction = fallback.normalized();
        }
        const long g = static_cast<long>(j) + (static_cast<long>(j) - static_cast<long>(i));
        if (g >= 0 && g < static_cast<long>(n) && m_cosLimit[j] > -1.0 + 1e-12) {
            Vec3 u = m_local[j] - m_local[static_cast<std::size_t>(g)];
            const double uLength = u.norm();
            if (uLength > 1e-300) {
                u /= uLength;
                const double c = direction.dot(u);
                if (c < m_cosLimit[j]) {
                    Vec3 w = direction - c * u;
                    if (w.norm() < 1e-12) w = u.unitOrthogonal();
                    direction = m_cosLimit[j] * u + m_sinLimit[j] * w.normalized();
                }
            }
        }
        length = std::clamp(length, m_minLength[segment], m_maxLength[segment]);
        const Vec3 target = m_local[j] + length * direction;
        if ((target - m_local[i]).squaredNorm() > 1e-26) {
            m_local[i] = moveSwept(i, m_local[i], target, false);
            changed = true;
        }
    };

    double penetration = pushOut();
    const double ctol = m_collisionOptions.constraintTolerance;
    UpdateResult violation = changed ? measureViolation() : UpdateResult();
    bool fixedMoved = false;
    for (std::size_t i = 0; i < n && !fixedMoved; ++i)
        fixedMoved = m_fixed[i] && m_local[i] != m_collisionStart[i];
    // The contacts as rows of the chain projection (the tangent plane at the closest point of
    // each collider near a free point, which the axis keeps the outer radius and a tenth of the
    // tolerance above) with every length and bend: at most kContactProjectionSteps Newton steps
    // from the pushed-out shape, the rest closed by the span solver when they end near. The
    // result is kept when the points get there swept without touching anything and nothing
    // penetrates; otherwise the contact rounds below go on from the swept shape. When the steps
    // end far off, the update is refused (below) unless a fixed point moved: then only the
    // rounds are left.
    bool projectionFailed = false;
    if (changed && (violation.status != Status::Ok || penetration > tolerance)) {
        const std::vector<Vec3> before = m_local;
        detail::ChainProjection projection(*this);
        projection.setRange(0, static_cast<int>(n) - 1);
        projection.useMassesFromRestLengths(grabbed);
        const double reach = radius + tolerance + maxRest;
        std::vector<double> contactDistance(n, std::numeric_limits<double>::infinity());
        for (std::size_t i = 0; i < n; ++i) {
            if (pinned[i]) continue;
            const MeshCollider::Closest c = contacts.closestToPoint(m_local[i] + m_origin, reach);
            if (c.found &&
                projection.setContact(static_cast<int>(i), c, m_origin, m_collisionStart[i],
                                      radius + 0.1 * tolerance, 1e-12))
                contactDistance[i] = c.distance;
        }
        // An edge between two points (the segment nearer to it than either point is to
        // anything): both points keep above the plane through the edge's closest point normal
        // to the way the segment lies from it, so the whole segment does.
        for (std::size_t s = 0; frameMoved && s + 1 < n; ++s) {
            const MeshCollider::Closest c = contacts.closestToSegment(
                m_local[s] + m_origin, m_local[s + 1] + m_origin, radius + tolerance);
            if (!c.found || !(c.distance > 0.0) || !c.normal.allFinite()) continue;
            for (const std::size_t i : {s, s + 1})
                if (!pinned[i] && c.distance < contactDistance[i]) {
                    projection.setContact(static_cast<int>(i), c.normal, c.onMesh - m_origin,
                                          radius + 0.1 * tolerance);
                    contactDistance[i] = c.distance;
                }
        }
        const detail::ProjectionOutcome out =
            projection.run(kContactProjectionSteps, kContactProjectionClose);
        result.iterations += out.iterations;
        if (out.converged && (measureViolation().status == Status::Ok ||
                              closeSpans(grabbed, before, result.iterations))) {
            const std::vector<Vec3> after = m_local;
            m_local = before;
            for (std::size_t i = 0; i < n; ++i)
                if (!pinned[i] && after[i] != before[i])
                    m_local[i] = moveSwept(i, before[i], after[i], false);
            penetration = pushOut(false);
            violation = measureViolation();
        } else {
            m_local = before;
            projectionFailed = true;
        }
    }
    // A moved collider has the rounds too: the previous shape it would fall back to may now be
    // across the collider.
    const bool runRounds = !projectionFailed || fixedMoved || frameMoved;
    for (int round = 0; changed && runRounds && round < m_collisionOptions.maxRounds; ++round) {
        if (violation.lengthViolation <= ctol && violation.angleViolation <= ctol &&
            penetration <= tolerance)
            break;
        for (std::size_t i = 1; i < n; ++i)
            if (!pinned[i]) project(i, i - 1);
        for (std::size_t i = n - 1; i-- > 0;)
            if (!pinned[i]) project(i, i + 1);
        penetration = pushOut();
        violation = measureViolation();
    }
    // Lengths are never given up to contacts: when the rounds leave a segment outside its band,
    // or the projection found no shape, and no fixed point moved (a grab, a gravity step), the
    // hose stays at its last collision-resolved shape (if that one keeps its lengths) and the
    // update is reported blocked. (Fixed points stay where their frames put them.) After a
    // collider moved, that shape may be one the collider moved into or across (its move
    // relative to the shape brings a segment's axis within the guard): then the rounds' shape
    // with its lengths and bends restored without the contacts (the chain projection, closed by
    // the span solver) is kept instead where it holds its lengths, being the nearer to outside.
    bool refused = false, repaired = false;
    if (changed && !fixedMoved && (violation.lengthViolation > ctol || !runRounds)) {
        const std::vector<Vec3> rounds = m_local;
        m_local = m_collisionStart;
        const UpdateResult kept = measureViolation();
        bool keptClear = true;
        for (std::size_t s = 0; frameMoved && keptClear && s + 1 < n; ++s) {
            const Vec3 a = m_local[s] + m_origin, b = m_local[s + 1] + m_origin;
            keptClear = !contacts.sweepSegment(a, b, a, b, guard, true).sweep.hit;
        }
        if (!keptClear) {
            m_local = rounds;
            detail::ChainProjection projection(*this);
            projection.setRange(0, static_cast<int>(n) - 1);
            projection.useMassesFromRestLengths(grabbed);
            const detail::ProjectionOutcome out =
                projection.run(kRepairProjectionSteps, kContactProjectionClose);
            result.iterations += out.iterations;
            if (out.converged && (measureViolation().status == Status::Ok ||
                                  closeSpans(grabbed, rounds, result.iterations))) {
                const UpdateResult held = measureViolation();
                if (held.lengthViolation <= ctol) {
                    repaired = true;
                    violation = held;
                    freeBound.assign(n, kUnknownClearance);
                    penetration = pushOut(false);
                }
            }
            if (!repaired) m_local = m_collisionStart;
        }
        if (!repaired && kept.lengthViolation <= ctol) {
            refused = true;
            violation = kept;
            penetration = 0.0;
            for (std::size_t i = 0; i < n; ++i) {
                const MeshCollider::Closest c =
                    contacts.closestToPoint(m_local[i] + m_origin, queryReach);
                if (c.found) penetration = std::max(penetration, radius - c.distance);
                freeBound[i] = c.found ? c.distance - radius : queryReach - radius;
            }
            if (m_gravityPrevious.size() == n) m_gravityPrevious = m_local;
        } else if (!repaired) {
            m_local = rounds;
        }
    }

    // A grab with no collider moved: the hose's whole move from the previous shape (every
    // segment's ends in straight lines) must keep every axis `guard` from the colliders, and
    // every length and bend must hold (1e-9). Otherwise the grab is made again, without contacts,
    // from the previous shape towards nearer points of the grabbed point's swept path
    // (kGrabFallbacks), the first whose move is clear and which penetrates nothing is kept, and
    // when none is, the previous shape stays. Either way the update is blocked.
    const bool checkGrab = grabbed >= 0 && startIsPrevious && !frameMoved;
    UpdateResult startViolation; // the previous shape's: a grab need not repair it
    if (checkGrab) {
        const std::vector<Vec3> reached = m_local;
        m_local = m_collisionStart;
        startViolation = measureViolation();
        m_local = reached;
    }
    auto grabMoveHolds = [&]() {
        const UpdateResult v = measureViolation();
        if (v.lengthViolation > std::max(1e-9, startViolation.lengthViolation) ||
            v.angleViolation > std::max(1e-9, startViolation.angleViolation))
            return false;
        for (std::size_t s = 0; s + 1 < n; ++s) {
            if (m_fixed[s] && m_fixed[s + 1]) continue;
            const Vec3 &a0 = m_collisionStart[s], &b0 = m_collisionStart[s + 1];
            const Vec3 &a1 = m_local[s], &b1 = m_local[s + 1];
            if (a0 == a1 && b0 == b1) continue;
            const double span = std::max({(a0 - a1).norm(), (b0 - a1).norm(), (b1 - a1).norm()});
            if (freeBound[s] + radius - span > guard) continue;
            if (contacts
                    .sweepSegment(a0 + m_origin, b0 + m_origin, a1 + m_origin, b1 + m_origin, guard,
                                  false)
                    .sweep.hit)
                return false;
        }
        return true;
    };
    bool grabHeldBack = false;
    if (checkGrab && !grabMoveHolds()) {
        const std::size_t k = static_cast<std::size_t>(grabbed);
        const Vec3 from = m_collisionStart[k];
        // A grab made again may slide clips (Hose::grab): with clips only the solver's shape
        // and the previous one are tried.
        const bool clips = std::any_of(m_attachments.begin(), m_attachments.end(),
                                       [](const Attachment& a) { return a.isClip(); });
        bool found = false;
        for (int attempt = 0; attempt <= (clips ? 0 : kGrabFallbacks) && !found; ++attempt) {
            if (attempt == 0) {
                m_local = solved; // the collision-free solver's shape towards grabReach
            } else {
                const double fraction = std::ldexp(1.0, -attempt);
                std::vector<std::shared_ptr<const MeshCollider>> colliders;
                colliders.swap(m_colliders); // the solve is a grab without colliders
                m_local = m_collisionStart;
                const UpdateResult redo =
                    grabWithoutContacts(grabbed, from + fraction * (grabReach - from) + m_origin);
                m_colliders.swap(colliders);
                result.iterations += redo.iterations;
            }
            freeBound.assign(n, kUnknownClearance);
            found = grabMoveHolds() && pushOut(false) <= tolerance;
        }
        if (!found) m_local = m_collisionStart;
        freeBound.assign(n, kUnknownClearance);
        penetration = pushOut(false);
        violation = measureViolation();
        refused = false;
        repaired = false;
        changed = true;
        grabHeldBack = true;
        if (result.status != Status::InvalidInput) result.status = Status::Clamped;
    }

    // Report: points touching, and both ends of a segment touching (an edge between them).
    std::vector<unsigned char> touchingPoint(n, 0);
    for (std::size_t i = 0; i < n; ++i)
        touchingPoint[i] = pointClearance(i, nullptr) < 2.0 * tolerance;
    for (std::size_t s = 0; s + 1 < n; ++s) {
        if (touchingPoint[s] && touchingPoint[s + 1]) continue; // counted already
        const double length = (m_local[s + 1] - m_local[s]).norm();
        if (std::min(freeBound[s], freeBound[s + 1]) >= 0.5 * length + 2.0 * tolerance) continue;
        const MeshCollider::Closest c = contacts.closestToSegment(
            m_local[s] + m_origin, m_local[s + 1] + m_origin, radius + 2.0 * tolerance);
        if (c.found) touchingPoint[s] = touchingPoint[s + 1] = 1;
    }
    result.contacts = static_cast<int>(std::count(touchingPoint.begin(), touchingPoint.end(), 1));
    result.penetration = penetration > tolerance ? penetration : 0.0;
    bool blocked = result.penetration > 0.0 || refused || grabHeldBack;
    if (grabbed >= 0) {
        const std::size_t k = static_cast<std::size_t>(grabbed);
        if ((m_local[k] - localTarget).norm() > result.grabError + tolerance) {
            blocked = true;
            if (result.status == Status::Ok) result.status = Status::Clamped;
        }
        result.grabError = (m_local[k] - localTarget).norm();
    }
    result.blocked = blocked;
    // Refused, or repaired without the contacts, and still inside a collider (one moved or
    // flagged onto the hose): the contact is not met, which the caller must not read as Ok.
    if ((refused || repaired) && result.penetration > 0.0 && result.status == Status::Ok)
        result.status = Status::Infeasible;
    if (changed) {
        result.lengthViolation = violation.lengthViolation;
        result.angleViolation = violation.angleViolation;
        m_dirtyViolation = violation.status != Status::Ok;
        if ((violation.lengthViolation > ctol || violation.angleViolation > ctol) &&
            result.status != Status::InvalidInput)
            result.status = Status::Infeasible;
        // Per-frame gravity (step()): a point a contact moved loses its velocity (the contact is
        // inelastic), or the Verlet step would turn the push-back into a bounce.
        if (m_gravityPrevious.size() == n)
            for (std::size_t i = 0; i < n; ++i)
                if (m_local[i] != solved[i]) m_gravityPrevious[i] = m_local[i];
        int moved = 0;
        for (std::size_t i = 0; i < n; ++i)
            moved += (m_local[i] - m_collisionStart[i]).squaredNorm() > 0.0;
        result.movedPoints = moved;
        ++m_revision;
    }
    finish();
}

} // namespace chaintube
