// ChainTube — one hose: its axis, constraints, attachments and the deformation solver.
#pragma once

#include "chaintube/collision.h"
#include "chaintube/material.h"
#include "chaintube/profile.h"
#include "chaintube/types.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

namespace chaintube {

namespace detail {
class ChainProjection;
class ReelAccess;
class SpanSolver;
struct Workspace;

/// A hose's scratch buffers (the solvers' vectors, kept between updates so that a frame does
/// not allocate them again). Not part of the hose's state: a copy starts without them.
class WorkspaceSlot
{
public:
    WorkspaceSlot() noexcept;
    ~WorkspaceSlot();
    WorkspaceSlot(const WorkspaceSlot&) noexcept;
    WorkspaceSlot& operator=(const WorkspaceSlot&) noexcept;
    WorkspaceSlot(WorkspaceSlot&&) noexcept;
    WorkspaceSlot& operator=(WorkspaceSlot&&) noexcept;
    Workspace& get(); ///< created on first use

private:
    std::unique_ptr<Workspace> m_workspace;
};
} // namespace detail

/// What an update did. Always look at status. Every update does a bounded amount of work
/// (UpdateResult::iterations) and, unless it says Infeasible, leaves every segment inside its
/// stretch band and every joint within its deflection limit (1e-9 relative / radians).
enum class Status {
    Ok,           ///< The request was met exactly.
    Clamped,      ///< A grab target was not reached in this update: it is beyond the hose's
                  ///< reach, or farther than this update's bounded work brings the point.
                  ///< grabError says how far off. Held (the same target again), the point comes
                  ///< nearer update by update, never farther, and comes to rest at the reachable
                  ///< position nearest to the target; the same target again at rest costs no
                  ///< work and leaves revision() as it was.
    Infeasible,   ///< Attachments whose frames leave no valid shape. Lengths are never given
                  ///< up: beyond the hose's reach, the moved attachment stops short of its frame,
                  ///< on the way towards it, and the hose is taut (attachmentGap() says how far
                  ///< off); ends whose positions and tangents leave no shape within the bend
                  ///< limits keep their lengths and give up bends as little as the projection
                  ///< can (angleViolation). Also a shape loaded in violation of its constraints
                  ///< that a grab could not repair (the grab then never makes it worse).
    InvalidInput, ///< Rejected (NaN/Inf, index out of range, grabbing a fixed point); the
                  ///< hose is unchanged.
};

const char* toString(Status status);

struct [[nodiscard]] UpdateResult
{
    Status status = Status::Ok;
    /// Largest length violation beyond the stretch band, relative to the rest length (0 = none).
    double lengthViolation = 0.0;
    /// Largest bend violation beyond the joint's deflection limit (radians, 0 = none).
    double angleViolation = 0.0;
    /// Distance (metres) between the requested grab target and where the point ended up.
    double grabError = 0.0;
    /// Number of axis points whose position changed.
    int movedPoints = 0;
    /// Collision (Hose::setColliders): a collider kept the update from being met — the grabbed
    /// point stopped short of its target (a wall, or a gap narrower than the hose: the hose never
    /// passes through, status becomes Clamped), or the hose could not be brought outside every
    /// collider (e.g. an attachment moved into an object; penetration says how deep).
    bool blocked = false;
    /// Collision: deepest remaining penetration (metres, 0 = none beyond
    /// CollisionOptions::tolerance): outerRadius() − the axis's distance to a collider's
    /// triangles, so at most outerRadius(). Collision works on surfaces: an axis point deep
    /// inside a closed object shows only where the hose crosses the object's surface.
    double penetration = 0.0;
    /// Collision: axis points touching a collider after the update (with both ends of a segment
    /// that touches one: an edge between two axis points).
    int contacts = 0;
    /// Work done: Newton steps of the span solver and the chain projection (each O(points of
    /// the span or range it solves)); 0 for the paper's propagation alone. Bounded per update
    /// (lib/README.md, "Pinned spans, reach and gravity").
    int iterations = 0;
    /// Under a budget (Hose::setBudget): the budget ran out before the update met its target
    /// (the grab target, the attachments' frames) or finished its gravity step. The hose is
    /// valid as the last whole step left it and goes on towards the same target in the next
    /// updates (Hose::step()). Always false without a budget. What no budgeted try advances is
    /// not pending for ever (lib/README.md, "A hard budget a frame"): a grab that stalls (3
    /// grabs in a row towards the same target gained less than 1 % of the error) rests, Clamped;
    /// an attachment move that advanced nothing, or crept, in 3 updates in a row towards the same
    /// frames lets the bends give way (Infeasible, angleViolation) and, when that advances
    /// nothing in 3 more, goes back to the tries that keep the bends if those crept, else rests
    /// short of its frames (Infeasible, attachmentGap()); a gravity step
    /// that found nothing valid in 3 steps in a row rests where it is.
    bool pending = false;
    /// With `pending`: how far the hose still is from the target (metres): the grabbed point's
    /// distance to where the grab goes (its target, or the nearest point within reach), the
    /// largest attachmentGap() of a move; 0 for a gravity step cut short.
    double remaining = 0.0;
    bool ok() const { return status == Status::Ok; }
};

/// A hard bound on the work of one update (Hose::setBudget), in Newton steps of the span solver
/// and the chain projection (UpdateResult::iterations), each O(points of the span or range it
/// solves). What an update cannot finish within it goes on in the next updates.
struct UpdateBudget
{
    /// Newton steps an update may take, ≥ 1; 0: no bound (each update converges as far as its
    /// own fixed limits take it, as in authoring: the editor's commit, `check`, the export).
    int newtonSteps = 0;
    /// The real-time default: the worst frame of the real-time benchmark's cases within about
    /// 3× the median frame's work (tests/bench/realtime/README.md).
    static UpdateBudget realtime() { return UpdateBudget{kRealtimeNewtonSteps}; }
    static constexpr int kRealtimeNewtonSteps = 16;
    bool bounded() const { return newtonSteps > 0; }
};

/// Per-frame gravity. When enabled, Hose::step(seconds) advances the hose by the frame's time
/// (call it once a frame; step() is a frame of 1/90 s); a hose at rest costs one comparison per
/// call. Hose::sag() settles to rest regardless of this switch.
struct Gravity
{
    bool enabled = false;
    Vec3 direction = Vec3(0.0, -1.0, 0.0); ///< world; need not be unit (finite, non-zero)
    /// step()'s frame (seconds), and the longest implicit step a frame is made of.
    static constexpr double kFrameSeconds = 1.0 / 90.0;
    /// The longest frame step(seconds) accepts (seconds): 9 implicit steps at most.
    static constexpr double kMaxFrameSeconds = 0.1;
};

/// Torsion as an optional degree of freedom: the roll of an attachment's frame about
/// the hose axis twists the rings; between two attachments the twist is spread over the joints
/// between them, at most twistLimit per joint.
struct Torsion
{
    bool enabled = false;
    double twistLimit = 0.1; ///< radians per joint, in (0, π]
};

/// How an attachment holds the hose.
enum class Hold {
    Fixed,         ///< its run of points moves rigidly with its frame (Hose::attach)
    Sliding,       ///< a clip: the axis passes through the clip's centre along the clip's axis and
                   ///< slides through it (Hose::addClip)
    SlidingTurning ///< a clip that also lets the hose turn about its axis: with torsion on it
                   ///< imposes no roll
};

const char* toString(Hold hold);

/// A clip's kind and end stops (Hose::addClip).
struct ClipOptions
{
    Hold hold = Hold::Sliding; ///< Sliding or SlidingTurning
    /// End stops: the clip's place along the hose (the rest arc length from point 0 to the
    /// clip's centre, metres) stays within [slideMin, slideMax]; the defaults are the hose's
    /// ends. slideMin ≤ the place the clip is added at ≤ slideMax.
    double slideMin = 0.0;
    double slideMax = std::numeric_limits<double>::infinity();
};

/// Parameters that make a hose.
struct HoseSpec
{
    double outerDiameter = 0.02; ///< metres, > 0
    Material material;
    /// Number of axis segments (points − 1), 1 … 1,000,000. If 0, segmentLength is used.
    int segmentCount = 0;
    /// Target axis segment length (metres) used when segmentCount is 0.
    double segmentLength = 0.02;
    /// Cross-section; when empty (vertexCount() == 0) a 16-sided circle of outerDiameter/2.
    Profile profile;
    /// Gravity sag during updates (beyond the paper, opt-in; costs nothing when off).
    Gravity gravity;
    /// Torsion (beyond the paper, opt-in; costs nothing when off).
    Torsion torsion;

    /// Throws InvalidArgument naming the field if a value is outside its range.
    void validate() const;
};

/// Gravity sag options (beyond the paper; optional, costs nothing unless used): Hose::sag().
struct SagOptions
{
    Vec3 gravityDirection = Vec3(0.0, -1.0, 0.0); ///< world, need not be unit (non-zero)
    int maxRounds = 4000;    ///< bound on the work: steps of Hose::step(), each O(n)
    double tolerance = 1e-7; ///< > 0; not used: rest is decided by step()'s rule
};

struct SagResult
{
    UpdateResult update;  ///< constraint state of the final shape
    int rounds = 0;       ///< steps used
    bool settled = false; ///< converged within maxRounds
};

/// A hose: a chain of axis points p0 … pn with per-segment rest lengths, a stretch band and a
/// per-joint deflection limit, plus attachments (runs of points fixed to frames).
///
/// Updates: a free end follows by the paper's outward propagation (O(n), exact). A span between
/// two pinned points (attachments, the held point) is solved in the span's own degrees of
/// freedom, its segments' directions (and lengths, within the band): every length and bend
/// limit holds by construction, damped Newton steps on the few closure rows (the far pin, a
/// point the span passes through) cost O(span) each, at most a fixed number per update; a grab
/// moves in steps that each end valid (lib/README.md, "Pinned spans, reach and gravity").
///
/// Positions are in world metres. Internally they are stored relative to a local origin
/// (the first axis point at construction) so that a hose 1e5 m from the world origin keeps
/// full precision in its constraints.
///
/// Degenerate cases the paper does not cover, decided here:
///  * Zero-length direction (a point dragged exactly onto its neighbour): the neighbour keeps
///    the direction it had before the move; if that is also undefined, the incoming segment's
///    direction; the resulting segment takes its minimum length.
///  * Fold-back (a bend request of exactly 180°): the bend plane is taken from the point's
///    previous position; if that is also degenerate, from a fixed perpendicular of the
///    incoming direction. Deterministic.
///  * A straight free span between two pinned points (fixed or grabbed) pushed shorter than
///    its segments' minimum lengths allow (e.g. the two end attachments of a straight
///    inextensible hose moved closer): on its line it cannot be shorter, so it is first laid on
///    the first buckling mode of a rod clamped at both pins, a (1 − cos 2πx/c)/2 over the chord
///    c, its length the span's rest length, bulging towards the same fixed perpendicular of the
///    line as the fold-back rule (line direction × the world axis it has the smallest component
///    along: +z for a span along +x, +x for one along +y); then solved as usual. If that does
///    not solve (e.g. a rigid hose), the update is decided from the straight state.
///  * Infeasible requests: see Status::Clamped and Status::Infeasible.
///  * A hose whose current shape violates its constraints (e.g. a route with corners sharper
///    than the bend limit, or after tightening the material) stays as it is until a point is
///    moved; settle() re-imposes the constraints, and with gravity on each step() brings it
///    nearer to valid.
class Hose
{
public:
    /// A straight hose of the given length (metres > 0) starting at start and running along
    /// direction (non-zero). Throws InvalidArgument.
    static Hose straight(const Vec3& start, const Vec3& direction, double length,
                         const HoseSpec& spec);

    /// A hose laid along a route (≥ 2 points, consecutive points distinct). Interior corners
    /// are rounded with the material's minimum bend radius (for a DeflectionAngle limit, the
    /// radius the angle gives at the segment length), limited by the available leg lengths;
    /// the axis is then sampled at equal arc length. Rest lengths are the sampled chords, so
    /// the hose starts relaxed. Throws InvalidArgument.
    static Hose alongRoute(const std::vector<Vec3>& route, const HoseSpec& spec);

    /// A hose through exactly these axis points (≥ 2, consecutive points distinct); their
    /// distances become the rest lengths. Throws InvalidArgument.
    static Hose fromAxis(const std::vector<Vec3>& axisPoints, const HoseSpec& spec);

    /// A hose whose current shape is `axisPoints` but whose rest lengths are given (metres,
    /// one per segment, each > 0 and finite): e.g. a hose saved or exported while deformed.
    /// The shape may violate the constraints; settle() or the next update re-imposes them.
    /// Throws InvalidArgument.
    static Hose fromAxis(const std::vector<Vec3>& axisPoints,
                         const std::vector<double>& restLengths, const HoseSpec& spec);

    // --- geometry -------------------------------------------------------------------------
    int pointCount() const { return static_cast<int>(m_local.size()); }
    int segmentCount() const { return pointCount() - 1; }
    /// World position of axis point i (0 ≤ i < pointCount()).
    Vec3 point(int i) const { return m_origin + m_local[static_cast<size_t>(i)]; }
    std::vector<Vec3> points() const;
    /// Local origin; localPoints()[i] + origin() is point(i).
    const Vec3& origin() const { return m_origin; }
    const std::vector<Vec3>& localPoints() const { return m_local; }

    double restLength(int segment) const { return m_restLength[static_cast<size_t>(segment)]; }
    double minLength(int segment) const { return m_minLength[static_cast<size_t>(segment)]; }
    double maxLength(int segment) const { return m_maxLength[static_cast<size_t>(segment)]; }
    /// Total rest length of the axis (metres).
    double restLengthTotal() const;
    /// Current length of the axis polyline (metres).
    double currentLength() const;
    /// Deflection limit at interior point j (1 ≤ j ≤ n−1), radians; π means unlimited.
    double deflectionLimit(int joint) const;

    const HoseSpec& spec() const { return m_spec; }
    const Material& material() const { return m_spec.material; }
    const Profile& profile() const { return m_spec.profile; }
    double outerRadius() const { return 0.5 * m_spec.outerDiameter; }

    /// Change material / profile / diameter (the axis keeps its rest lengths). Limits are
    /// recomputed; call settle() to re-impose them on the current shape. Throws InvalidArgument.
    void setMaterial(const Material& material);
    void setProfile(const Profile& profile);
    void setOuterDiameter(double metres);

    // --- interaction ----------------------------------------------------------------------
    /// Move free axis point `index` to `target` (world) and let the rest of the hose follow;
    /// the point is held (heldPoint()) until the next grab or releaseGrab(). Fixed points never
    /// move. Between fixed points the point goes towards the target in steps that each end
    /// valid, at most a fixed number a call; a target beyond reach is replaced by the nearest
    /// point within the reach of both sides. O(n) a step. A grab between fixed points that
    /// would move no point by more than 1e-9 of the mean rest length (a point held still, its
    /// target the same each frame) moves nothing (movedPoints 0, revision() unchanged), and
    /// the same target again from the shape a grab left unmoved costs one comparison. See
    /// Status.
    UpdateResult grab(int index, const Vec3& target);

    /// Fix the run of points first … last (inclusive, 0 ≤ first ≤ last < pointCount(), not
    /// overlapping another attachment) rigidly to `frame` at their current positions.
    /// Returns the attachment id (stable until detached). Throws InvalidArgument.
    int attach(int first, int last, const Frame& frame);
    /// Move an attachment's frame; its points move rigidly and the rest of the hose follows in
    /// the same update. A frame beyond the hose's reach from the neighbouring fixed points
    /// leaves the attachment short of it (Status::Infeasible, attachmentGap()); moved back
    /// within reach it is met again. A move of more than two segment lengths that finds no
    /// shape is made again in two halves (each split the same way, at most twice): a long jump
    /// of a part is followed as a drag would be. An unknown id or a non-finite frame gives
    /// Status::InvalidInput and changes nothing.
    UpdateResult moveAttachment(int id, const Frame& frame);
    /// Move several attachments at once (one update); ids and frames have equal size.
    UpdateResult moveAttachments(const std::vector<int>& ids, const std::vector<Frame>& frames);
    /// Remove an attachment or a clip; its points become free. Unknown id: returns false.
    bool detach(int id);

    /// A clip (guide) on a scene part's `frame`, where the hose is now at rest arc length
    /// `place` from point 0 (0 ≤ place ≤ restLengthTotal(), within the options' end stops):
    /// the clip's centre is that point of the axis, its axis the direction of the segment
    /// there, both kept in the frame. The hose's axis then passes through the centre along the
    /// clip's axis and may slide through it (lib/README.md, "Clips"): the segment that holds
    /// the centre is held on the clip's axis (like a one-segment attachment) and moves along
    /// it as the hose slides; total length is conserved. Moving the frame (moveAttachments)
    /// carries the clip; every grab and attachment move first slides the hose through its clips
    /// where one side needs more length than it has and the other can give it. The segment
    /// may not hold a point another attachment fixes. Returns the id (shared with attach()).
    /// Throws InvalidArgument.
    int addClip(double place, const Frame& frame, const ClipOptions& options = ClipOptions());

    struct Attachment
    {
        int id = 0;
        int first = 0;
        int last = 0;
        Frame frame;
        std::vector<Vec3> localPoints; ///< positions of first…last in the frame
        Hold hold = Hold::Fixed;
        // Clips (hold ≠ Fixed): first … last is the segment holding the centre (last = first+1).
        Vec3 clipCentre = Vec3::Zero();        ///< in the frame
        Vec3 clipAxis = Vec3::UnitX();         ///< in the frame, unit, pointing towards `last`
        double slide = 0.0;                    ///< the centre's rest arc length from point 0
        double slideMin = 0.0, slideMax = 0.0; ///< end stops
        bool isClip() const { return hold != Hold::Fixed; }
    };
    const std::vector<Attachment>& attachments() const { return m_attachments; }
    bool isFixed(int index) const;
    /// How far an attachment is from being met (metres): the largest distance between where
    /// its frame puts one of its points and where that point is. 0 while it is met; > 0 when
    /// its frame was moved beyond the hose's reach (see Status::Infeasible). Unknown id: −1.
    double attachmentGap(int id) const;

    /// Re-impose all constraints on the current shape (after a material change or on a shape
    /// built from raw points): propagates from the fixed points (or from point 0 if none).
    UpdateResult settle();

    /// Let the free points settle under gravity to rest, every constraint holding: step() in
    /// `options.gravityDirection` until the hose is at rest or maxRounds steps ran out
    /// (`settled` false; the shape is then the last step's, valid). The held point is released
    /// for the duration. Deterministic. Without a fixed point, or with a non-finite or zero
    /// direction: InvalidInput, the hose unchanged. With colliders their contacts hold too.
    SagResult sag(const SagOptions& options = SagOptions());

    /// Per-frame gravity (HoseSpec::gravity; beyond the paper): one implicit step of 1/90 s.
    /// The free points' predicted positions (their velocity, damped to 0.9 a step, plus the
    /// fall under 9.81 m/s²) are projected onto the constraints by at most 8 O(n) Newton steps
    /// of the smallest mass-weighted move: every length in its band, every joint within its
    /// limit and, with colliders, every point outerRadius() outside the tangent plane of its
    /// nearest collider (a touching point keeps no velocity); a projection that ends close is
    /// finished exactly by the span solver. While the held point moves from step to step, the
    /// projection stops within 1e-3 (1e-5 near a collider) and the span solver finishes; once it
    /// stands still (to rounding), the projection converges, so a hose held still comes to rest.
    /// Bounded: at most 4 attempts (then from rest, with the fall of the last retry that worked, a
    /// quarter of it and a sixteenth of the full fall, never below that sixteenth; while a point is
    /// held, once the full prediction failed, the next 8 steps start with that retry fall and the
    /// velocity instead); when none ends valid the hose stays where it is, at rest. After every
    /// call every constraint holds (1e-9). Moves made by grabs and attachments carry no velocity;
    /// fixed points and the held point (the last grabbed, until releaseGrab()) stay. A shape that
    /// violates its constraints is brought nearer to valid instead of falling. At rest (no point
    /// moved more than 1e-6 of a mean segment in a step, or no lower by 1 % of a mean segment in
    /// 120 steps), with gravity off, or with nothing fixed and nothing held, a call costs one
    /// comparison until an input changes (any revision()). Deterministic. Returns the constraint
    /// state; movedPoints is 0 when nothing was done, iterations the Newton steps. Under a budget
    /// (setBudget) it first goes on with a grab or attachment move that ran out of it, unless a
    /// new one came in since the last step(), then steps within what is left; a gravity step cut
    /// short by the budget is `pending` and never taken for rest. Call it once a frame.
    /// step() is step(Gravity::kFrameSeconds).
    UpdateResult step();
    /// step() for a frame of `seconds` in (0, Gravity::kMaxFrameSeconds]: ⌈seconds · 90⌉ equal
    /// implicit steps of at most 1/90 s (each as above, its fall, damping and rest rule taken
    /// for its length), so the same timed path of the attachments gives the same shape at any
    /// frame rate (lib/README.md, "Gravity at any frame rate"); moves made by grabs and
    /// attachments carry no velocity, so nothing whips. Under a budget the steps take the
    /// frame's budget in turn; once none is left the frame's later steps are dropped and the
    /// hose is `pending`. Non-finite, ≤ 0 or > kMaxFrameSeconds: Status::InvalidInput, nothing
    /// changes (not even a pending update goes on).
    UpdateResult step(double seconds);
    /// Bounds the work of every later update (grab, attachment moves, step(), resolveCollisions(),
    /// clip slides within them) to `budget` (UpdateBudget{} lifts the bound; sag() and settle()
    /// are never bounded). An update that runs out of it stops at the last valid shape it reached
    /// (every length and bend within 1e-9, no new penetration) and reports `pending`; each step()
    /// after it then goes on towards the same target (the grab target, the attachments' frames)
    /// within the budget, unless a grab or attachment move came in since the last step(), until
    /// the target is met, the update ends as it would without a budget, or it stalls and rests
    /// (UpdateResult::pending): every update's work stays within the budget. Throws
    /// InvalidArgument for newtonSteps < 0.
    void setBudget(const UpdateBudget& budget);
    const UpdateBudget& budget() const { return m_budget; }
    /// An update ran out of its budget and step() will go on with it (UpdateResult::pending).
    bool pending() const { return m_pendingGrab || m_pendingMove || m_pendingFall; }
    /// With pending(): how far the hose still is from the pending target (metres): the held
    /// point's distance to where its grab goes, the largest attachmentGap() of a pending
    /// attachment move, whichever is larger; 0 for a gravity step cut short, or nothing pending.
    double remaining() const;
    /// Goes on now, without the budget, with a grab or attachment move that ran out of it (e.g.
    /// an editor's live drag when the mouse is released): one unbounded update towards the same
    /// target. Nothing pending: does nothing (movedPoints 0).
    UpdateResult finishPending();

    /// The point held by the last grab (−1: none). A held point is fixed for step() and
    /// releaseGrab() frees it; a grab of another point moves the hold there.
    int heldPoint() const { return m_held; }
    void releaseGrab();
    /// Takes the current shape as the rest state under gravity: step() leaves the hose as it is
    /// until an input changes (any revision()), and no velocity or contact state is carried
    /// (the next fall starts from rest, as in a hose just built). For a hose loaded in the shape
    /// it settled in: the export writes gravity hoses settled (formats::settleUnderGravity) and
    /// the runtime starts them with this, so they do not drop or creep when loaded.
    void markSettled();

    /// Incremented whenever an axis point, the profile or the diameter changes; renderers and
    /// the scene use it to skip hoses whose inputs did not change.
    std::uint64_t revision() const { return m_revision; }

    // --- collision with scene objects (opt-in, one branch per update without) ---------------
    /// Make the hose stay outside these colliders (shared with other hoses; moving a collider's
    /// frame moves it for all). Every grab, attachment move and gravity step then ends with a
    /// continuous check of each moved point from its previous position (a sphere of
    /// outerRadius() sweeps from the last collision-free shape; it stops at contact and slides,
    /// so the hose never tunnels through thin walls or gaps narrower than its diameter) and of
    /// each segment (MeshCollider::sweepSegment: a plate or a knife edge between two axis points
    /// stops it too), then bounded contact rounds that re-impose the length band and bend limits
    /// with every move again swept (CollisionOptions). Residual
    /// constraint violations are reported in the UpdateResult; status becomes Infeasible only
    /// when they exceed options.constraintTolerance. An empty list turns collision off. The
    /// current shape is taken as the starting state: call resolveCollisions() if it may
    /// already intersect. Throws InvalidArgument for a null collider or options out of range.
    void setColliders(std::vector<std::shared_ptr<const MeshCollider>> colliders,
                      const CollisionOptions& options = CollisionOptions());
    const std::vector<std::shared_ptr<const MeshCollider>>& colliders() const
    {
        return m_colliders;
    }
    const CollisionOptions& collisionOptions() const { return m_collisionOptions; }
    /// Push the hose out of its colliders now (after moving a collider's frame, or after
    /// setColliders on a shape that intersects): points inside are moved out on the side
    /// their centre is on, then the contact rounds run. A collider moving farther than the
    /// hose radius in one step can pass through a hose (discrete for moving colliders).
    UpdateResult resolveCollisions();

    /// Largest violation of the length band (relative) and of the deflection limits (rad).
    UpdateResult measureViolation() const;

private:
    Hose() = default;
    void initialiseFromAxis(const std::vector<Vec3>& axisPoints, const HoseSpec& spec);
    void recomputeLimits();
    /// −1: fixed points only before `index`; +1: only after it; 0: on both sides or none.
    int pinnedSide(int index) const;
    /// The attachment (or clip) with this id, or null.
    Attachment* attachmentWithId(int id);
    const Attachment* attachmentWithId(int id) const;
    bool blendSide(int from, int side, const Vec3& displacement);
    /// moveAttachments: one update, and the halvings of a long move that found no shape.
    UpdateResult moveAttachmentsOnce(const std::vector<int>& ids, const std::vector<Frame>& frames);
    /// moveAttachmentsOnce() without the contact step (solver.cpp).
    UpdateResult solveAttachmentMove(const std::vector<int>& ids, const std::vector<Frame>& frames);
    /// grab() in parts (solver.cpp): whether it accepts the index and target; the solve without
    /// colliders (within the update's BudgetScope; `answered`: the same target again, answered
    /// at once, nothing else to do); and its bookkeeping after the contact step (pending, the
    /// stalls, the target remembered). The update is grab() (update.cpp): solve, contact step,
    /// finish; grabWithoutContacts() is the same without the contact step (hose_contact.cpp's
    /// grabs made again).
    struct GrabSolve
    {
        UpdateResult result;
        Vec3 goal = Vec3::Zero();         ///< where the point goes (local): target or in reach
        std::uint64_t revisionBefore = 0; ///< revision() before the update
        int moved = 0;                    ///< points the solve moved
        bool slidesMissed = false;        ///< clip slides were tried and came to nothing
        bool answered = false;
    };
    bool grabAccepts(int index, const Vec3& target) const;
    GrabSolve solveGrab(int index, const Vec3& target);
    UpdateResult finishGrab(int index, const Vec3& target, const GrabSolve& solve, bool budgetCut);
    UpdateResult grabWithoutContacts(int index, const Vec3& target);
    UpdateResult moveAttachmentsInSteps(const std::vector<int>& ids,
                                        const std::vector<Frame>& frames, int halvings);
    bool blendTowardsPins(int index, const Vec3& displacement);

    /// Clips: slide the hose through each clip whose one side needs more length to reach its
    /// pinned points (the held point at `heldTarget` when given) and whose other side can
    /// spare it, the short side fed to `margin` (a fraction) inside its reach (lib/README.md,
    /// "Clips"). `shifts`: (clip id, how far its centre moved along its axis) of the clips an
    /// attachment move moved, or null; such a clip starts from the slide at which the hose
    /// stays where it is. Re-places the clips that slid (their segment, its fixed flags and
    /// positions on the clip's axis) and returns their ids.
    std::vector<int> slideClips(int held, const Vec3* heldTarget, double margin,
                                const std::vector<std::pair<int, double>>* shifts = nullptr);
    /// Puts clip `a` at slide position `s` (its segment, fixed flags, local points, and its
    /// two points at the frame).
    void placeClip(Attachment& a, double s);

    /// settle(), with `held` (≥ 0) pinned like a fixed point.
    UpdateResult settleFrom(int held);
    /// Makes a shape that nearly holds its constraints hold them exactly, without giving way:
    /// the spans between pinned points (fixed, and `held` ≥ 0) by the span solver from the
    /// current positions, the free tails by the paper's pass (`before`: the positions before
    /// the update, for its fold-back rule). Bounded (the span solver's steps per span, one
    /// pass). Returns whether every constraint holds; the points may have moved either way.
    bool closeSpans(int held, const std::vector<Vec3>& before, int& iterations);
    /// The first and last point of the attachments and `held` (first > last: nothing pinned).
    std::pair<int, int> pinnedRangeOf(int held) const;
    /// The paper's pass over the free tails beyond pinnedRangeOf(held), every tail point placed
    /// from where it is (solver.cpp). `before`: the positions before the update.
    void followTails(int held, const std::vector<Vec3>& before);
    /// Turn at joint j of `points` beyond its limit (radians; negative: within it).
    double turnExcess(size_t j, const std::vector<Vec3>& points) const;

    /// The bounded update (Hose::setBudget): Newton steps an update may still take (−1: no
    /// bound), whether a solver stopped because of it, and the outermost update's scope.
    friend class BudgetScope;
    friend class BudgetShare;
    int budgetedSteps(int wanted) const
    {
        return m_budgetLeft < 0 ? wanted : std::min(wanted, m_budgetLeft);
    }
    /// A solver took `steps` Newton steps out of `allowed` = budgetedSteps(`wanted`).
    void spendSteps(int steps, int allowed, int wanted)
    {
        if (m_budgetLeft < 0) return;
        m_budgetLeft = std::max(0, m_budgetLeft - steps);
        if (steps >= allowed && allowed < wanted) m_budgetCut = true;
    }
    /// step(): one implicit gravity step of `seconds` alone (sag.cpp).
    UpdateResult stepGravity(double seconds);
    /// step(): goes on with a pending grab or attachment move (solver.cpp).
    UpdateResult continuePending();

    friend class Solver;
    friend class GravityStep;
    friend class PinnedSpans;
    friend class detail::ChainProjection;
    friend class detail::ReelAccess; ///< reel.cpp: changes the point count in place
    friend class detail::SpanSolver;
    HoseSpec m_spec;
    Vec3 m_origin = Vec3::Zero();
    std::vector<Vec3> m_local;
    std::vector<double> m_restLength;
    std::vector<double> m_minLength;
    std::vector<double> m_maxLength;
    std::vector<double> m_minLengthBefore; ///< per point: sum of the minimum lengths before it
    std::vector<double> m_cosLimit;        ///< per point (0 and n unused = -1)
    std::vector<double> m_sinLimit;
    std::vector<double> m_limitAngle; ///< atan2(m_sinLimit, m_cosLimit): the limit in radians
    std::vector<double> m_cosHalfLimit;
    std::vector<double> m_sinHalfLimit;
    std::vector<double> m_chordLimit2; ///< 4 sin²(θ/2) + tolerance, the solver's turn test
    std::vector<unsigned char> m_fixed;
    std::vector<Attachment> m_attachments;
    std::vector<Vec3> m_scratch; ///< the shape before the current update (restored if it fails)
    detail::WorkspaceSlot m_workspace; ///< the solvers' buffers (workspace.h)
    int m_nextAttachmentId = 1;
    int m_held = -1;                  ///< see heldPoint()
    int m_edgePoint = -1;             ///< point of the last grab, if it moved nothing
    std::uint64_t m_edgeRevision = 0; ///< m_revision right after that grab
    Vec3 m_edgeTarget = Vec3::Zero(); ///< that grab's local target
    UpdateResult m_edgeResult;        ///< and what it returned
    bool m_edgeSlidesMissed = false;  ///< and its clip slides came to nothing
    /// grab(): the last grab's point, target, error and the shape it left (m_revision), and how
    /// many grabs in a row towards that target from the shape the one before left brought the
    /// point less than kStalledGain of its error nearer (a budgeted grab stalls: solver.cpp).
    struct GrabStall
    {
        int point = -1;
        std::uint64_t revision = 0;
        Vec3 target = Vec3::Zero();
        double error = 0.0;
        int count = 0;
    };
    GrabStall m_grabStall;
    std::vector<Vec3> m_gravityPrevious;      ///< step(): positions one step back (velocity)
    std::vector<Vec3> m_gravityLast;          ///< step(): positions when the last step ended
    std::uint64_t m_settledRevision = 0;      ///< step(): revision at which the hose settled
    std::uint64_t m_gravityInputRevision = 0; ///< step(): revision the last step left
    double m_gravityLowestEnergy = 0.0; ///< step(): lowest potential energy since an input changed
    double m_gravityStallSeconds = 0.0; ///< step(): time since it last fell
    double m_gravityStepSeconds = Gravity::kFrameSeconds; ///< step(): the last step's length
    double m_gravityRetryFall = 1.0;                      ///< step(): fall of a retry (sag.cpp)
    bool m_gravityFullFailed = false; ///< step(): the last full prediction failed (sag.cpp)
    int m_gravitySkippedFull = 0;     ///< step(): full predictions skipped since (sag.cpp)
    bool m_dirtyViolation = false;    ///< last update left a violation: next one checks globally
    /// The chain projection's working set (projection.h), 3 per point: contact, length (+1
    /// upper bound, −1 lower), bend; kept from Newton step to Newton step of one projection.
    std::vector<signed char> m_workingSet;
    std::uint64_t m_revision = 1;
    /// SpanSolver::advance: where the last grab stopped short of its (reach-clamped) goal (its
    /// point, its trust radius, the goal), from which the next grab of the same point and goal
    /// goes on; and whether that grab got the point no nearer at all.
    struct TrustCarry
    {
        int point = -1;
        double radius = 0.0;
        Vec3 goal = Vec3::Zero();
        bool stalled = false;
        double reachMetric = 0.0; ///< SpanSolver::reach's metric it ended with (0: none yet)
    };
    TrustCarry m_trustCarry;

    UpdateBudget m_budget;      ///< see setBudget()
    int m_budgetLeft = -1;      ///< Newton steps the current update may still take (−1: any)
    bool m_budgetCut = false;   ///< a solver of the current update stopped for the budget
    int m_updateDepth = 0;      ///< BudgetScope: nesting of update entry points
    bool m_pendingGrab = false; ///< the last grab ran out of budget (its point m_held)
    double m_pendingGrabRemaining = 0.0;     ///< its UpdateResult::remaining
    Vec3 m_pendingGrabTarget = Vec3::Zero(); ///< its target (world)
    bool m_pendingMove = false;              ///< an attachment move ran out of budget
    /// Under a budget: the fraction of the way an attachment move tries first (solver.cpp)
    double m_moveFraction = 1.0;
    /// Under a budget: attachment-move updates in a row in which no try advanced (or one crept),
    /// whether the tries let the bends give way, and whether the updates before that crept
    /// (solver.cpp, kStalledMoves).
    struct MoveStall
    {
        int count = 0;
        bool givingWay = false;
        bool crept = false;
    };
    MoveStall m_moveStall;
    bool m_pendingFall = false; ///< the last gravity step ran out of budget
    /// Under a budget: gravity steps in a row cut short that found nothing valid (sag.cpp)
    int m_gravityStalls = 0;
    bool m_updatedSinceStep = false; ///< a grab or attachment move since the last step()

    /// Collision hook at the end of every update entry point (hose_contact.cpp, called from
    /// update.cpp and sag.cpp); no-op without colliders. `grabbed` is the grabbed point (−1 if
    /// none) and its requested local target.
    void applyCollisions(UpdateResult& result, int grabbed, const Vec3& localTarget);
    std::vector<std::shared_ptr<const MeshCollider>> m_colliders;
    CollisionOptions m_collisionOptions;
    std::vector<Vec3> m_collisionStart;    ///< last collision-resolved shape (local)
    std::vector<double> m_collisionFree;   ///< per point: clearance left before a query is needed
    std::vector<Frame> m_colliderFrames;   ///< collider frames at the last resolve
    std::uint64_t m_collisionRevision = 0; ///< m_revision when m_collisionStart was taken
};

} // namespace chaintube
