// ChainTube — motion sweeps: every moving part of a project (project.motions: hinges and
// sliders) driven through its range, the hoses updated at each step as the runtime updates
// them, and per hose the worst stretch, the smallest bend radius, the clearance to each scene
// object and every update that was not Ok, each with the step where it occurs. Used by
// `chaintube check --sweep` (exporters/README.md, "Motion sweeps").
#pragma once

#include "chaintube/export/clearance.h"
#include "chaintube/formats/project_hoses.h"
#include "chaintube/hose.h"

#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace chaintube::exporting {

/// One step of a sweep: where every motion is.
///
/// The rule: all motions are driven together by one parameter t ∈ [0, 1], motion i at
/// minimum_i + t · (maximum_i − minimum_i); t goes from 0 to 1 in N steps and back to 0 in N
/// steps. The sweep starts at the project's pose (every value 0, step 0) and reaches t = 0
/// through a lead-in of L steps, values_i = minimum_i · k / L (k = 1 … L), where L is the
/// smallest count whose steps are no larger than a sweep step for any motion
/// (L = ceil(N · max_i(−minimum_i / (maximum_i − minimum_i))), 0 when every minimum is 0).
/// Steps: 1 + L + 2N.
struct SweepStep
{
    enum class Phase {
        ProjectPose, ///< step 0: the hoses as built (every value 0)
        LeadIn,      ///< from the project's pose to t = 0
        Out,         ///< t from 0 to 1
        Back         ///< t from 1 back to 0
    };
    Phase phase = Phase::ProjectPose;
    /// The drive parameter; none before the path starts (the project's pose when it is not
    /// t = 0, the lead-in but its last step).
    std::optional<double> t;
    std::vector<double> values; ///< per project.motions: radians (hinge) or metres (slider)
};

/// "project pose", "lead-in", "out" or "back".
const char* toString(SweepStep::Phase phase);

/// The steps of a sweep of `motions` with `steps` (N ≥ 1) steps each way (the rule above).
/// Throws InvalidArgument for N < 1 or an empty motion list.
std::vector<SweepStep> sweepSchedule(const std::vector<formats::PartMotion>& motions, int steps);

struct SweepOptions
{
    int steps = 20; ///< N: steps each way, 1 … 100,000
    /// Metres ≥ 0: a hose surface nearer than this to an object is a violation (0: only
    /// collisions, distance < 0).
    double clearanceThreshold = 0.0;
    /// Metres ≥ 0: an object is listed for a hose when it comes nearer than
    /// max(reportDistance, clearanceThreshold) at some step; farther objects are not searched.
    double reportDistance = 0.05;
    /// As ClearanceOptions::includeAttachedNodes (the exemption rule of collider_exemption.h).
    bool includeAttachedNodes = false;
    /// Gravity hoses: at most this many Hose::step() calls after each step's move (fewer when
    /// the hose comes to rest), 0 … 100,000. Bounds the work per step.
    int gravityStepsPerStep = 30;
    /// Called with the fraction done (0 … 1) after the hoses are built and after each step;
    /// returning false cancels the sweep (throws formats::Cancelled).
    std::function<bool(double)> progress;
    /// Called after each step's updates with its index and the hoses (project order): for
    /// plots over the motion and for tests.
    std::function<void(int step, const std::vector<Hose>& hoses)> onStep;
    /// A project without motions: measure its pose as the one step of the report (step 0,
    /// Phase::ProjectPose) instead of returning a report with no steps. Length fitting
    /// (fit_length.h) fits such a project over its pose alone.
    bool measurePoseWithoutMotions = false;
};

/// Where one hose comes closest to one scene object over the sweep.
struct ObjectSweep
{
    int object = -1; ///< index in sceneObjects(project, scenes)
    std::string sceneId;
    std::string objectPath;
    double minDistance = std::numeric_limits<double>::infinity(); ///< metres, < 0: inside
    int step = -1;                                                ///< where minDistance occurs
    int axisPoint = -1;
    Vec3 onHose = Vec3::Zero();
    Vec3 onObject = Vec3::Zero();
    /// Steps with distance < the clearance threshold: how many, the first and the last (−1).
    int stepsBelowThreshold = 0;
    int firstStepBelowThreshold = -1;
    int lastStepBelowThreshold = -1;
    bool collides() const { return minDistance < 0.0; }
};

/// An update of a step whose status was not Ok (its moves and gravity steps combined: the
/// worst status, the largest violations).
struct SweepUpdate
{
    int step = -1;
    Status status = Status::Ok;
    double lengthViolation = 0.0; ///< relative, beyond the stretch band
    double angleViolation = 0.0;  ///< radians beyond a joint's limit
    double attachmentGap = 0.0;   ///< metres: the largest Hose::attachmentGap after the step
};

/// One hose over the sweep. Steps index SweepReport::steps.
struct HoseSweep
{
    int hose = -1; ///< index in project.hoses
    std::string hoseId;
    bool driven = false;        ///< an attachment of it sits on a part a motion carries
    double stretchBand = 0.0;   ///< the material's expansion coefficient
    double minBendRadius = 0.0; ///< the material's minimum bend radius (0: none or an angle limit)
    /// The largest |l / l0 − 1| of a segment, the step and the segment.
    double worstStretch = 0.0;
    int worstStretchStep = -1;
    int worstStretchSegment = -1;
    /// Steps where a segment left its stretch band (measure()'s lengthViolation above 1e-9, or
    /// above CollisionOptions::constraintTolerance for a hose with colliders: what the library
    /// guarantees after an update).
    int overstretchedSteps = 0;
    int firstOverstretchedStep = -1;
    /// The smallest bend radius (metres, measure(): from the turn and the current segment
    /// lengths; infinity for a hose straight at every step), the step and the joint.
    double smallestBendRadius = std::numeric_limits<double>::infinity();
    int smallestBendRadiusStep = -1;
    int smallestBendRadiusJoint = -1;
    /// Steps where a joint turned beyond its deflection limit (measure()'s angleViolation, with
    /// the tolerance of the stretch). For a minimum bend radius the limit is the angle it gives
    /// at the rest segment length, so a segment compressed within its band shows a radius below
    /// the minimum by that much without breaking the limit.
    int bendViolationSteps = 0;
    int firstBendViolationStep = -1;
    /// Beyond reach: the largest Hose::attachmentGap (metres; measure()'s unmet attachments,
    /// gaps above 1e-9 m), its step, and the steps with one.
    double worstAttachmentGap = 0.0;
    int worstAttachmentGapStep = -1;
    int unmetSteps = 0;
    int firstUnmetStep = -1;
    /// Objects that came within the report distance, nearest first.
    std::vector<ObjectSweep> objects;
    /// Every step whose update was not Ok.
    std::vector<SweepUpdate> updates;
    /// Per step: the largest |l / l0 − 1|, the smallest bend radius (infinity: straight) and
    /// the smallest distance to a listed object (infinity: none within the report distance).
    std::vector<double> stretchSeries, bendRadiusSeries, clearanceSeries;

    bool overstretched() const { return overstretchedSteps > 0; }
    bool bendViolated() const { return bendViolationSteps > 0; }
    bool beyondReach() const { return unmetSteps > 0; }
    /// An object nearer than the threshold (a collision included).
    bool belowClearance() const
    {
        for (const ObjectSweep& object : objects)
            if (object.stepsBelowThreshold > 0) return true;
        return false;
    }
    bool collides() const
    {
        for (const ObjectSweep& object : objects)
            if (object.collides()) return true;
        return false;
    }
    /// A limit broken at some step: stretch beyond the band, a bend beyond the limit, an
    /// attachment beyond reach, an object nearer than the threshold or a collision.
    bool violates() const
    {
        return overstretched() || bendViolated() || beyondReach() || belowClearance() || collides();
    }
};

struct SweepReport
{
    std::vector<formats::PartMotion> motions; ///< project.motions
    std::vector<SweepStep> steps;             ///< empty when the project has no motions
    std::vector<HoseSweep> hoses;             ///< project order
    int stepsEachWay = 0;                     ///< N
    int leadInSteps = 0;                      ///< L
    double clearanceThreshold = 0.0;
    double reportDistance = 0.0;
    bool violations() const
    {
        for (const HoseSweep& hose : hoses)
            if (hose.violates()) return true;
        return false;
    }
};

/// Builds the project's hoses as the clearance check does (formats::buildHose, gravity hoses
/// settled as they hang), gives them the project's colliders as the runtime does (minus the
/// exempt ones), and drives every motion through the schedule of sweepSchedule(). At each step
/// the moving parts get their transforms (formats::PartMotions), every hose with attachments
/// on carried nodes gets one Hose::moveAttachments() to their new frames (the runtime's
/// setNodeTransform for all moving parts at once), moved colliders are placed again (a hose
/// with none of its attachments moved but a moved collider gets Hose::resolveCollisions()),
/// gravity hoses take at most gravityStepsPerStep Hose::step() calls, and every hose is
/// measured: measure(), and clearance() to each object whose bounds come within the report
/// distance (a pair is measured again only when the hose or the object moved). `scenes` at
/// their file pose. A project without motions gives a report with no steps and no hoses, or
/// with SweepOptions::measurePoseWithoutMotions one step: the project's pose.
/// Throws InvalidArgument for options out of range or a motion naming an unknown node, and
/// formats::Cancelled when progress returns false.
SweepReport sweepMotions(const formats::Project& project, const formats::ImportedScenes& scenes,
                         const SweepOptions& options);

/// Loads the project, imports its scenes and sweeps it (the whole of `chaintube check
/// --sweep`). A project without motions is not imported: the report has no steps. Throws the
/// formats errors (file, format, path) and as sweepMotions.
SweepReport sweepProject(const std::filesystem::path& projectFile, const formats::NamedRoots& roots,
                         const SweepOptions& options);

/// The report as JSON text for pipelines (the fields: exporters/README.md, "Motion sweeps").
/// Infinite distances and radii are written as null.
std::string sweepReportJson(const SweepReport& report, const std::string& projectFile);

} // namespace chaintube::exporting
