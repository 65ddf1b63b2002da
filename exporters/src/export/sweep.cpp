// Motion sweeps: the project's moving parts driven through their ranges, the hoses followed
// and measured at every step.
#include "chaintube/export/sweep.h"

#include "chaintube/formats/errors.h"
#include "chaintube/formats/motion.h"
#include "chaintube/metrics.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

namespace chaintube::exporting {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
/// measure()'s tolerance for a violated length or bend (lib/README.md: constraints hold to
/// 1e-9 after an Ok update).
constexpr double kViolationTolerance = 1e-9;

int severity(Status status)
{
    switch (status) { // no default: a new status must be ranked here
    case Status::Ok:
        return 0;
    case Status::Clamped:
        return 1;
    case Status::Infeasible:
        return 2;
    case Status::InvalidInput: // the sweep's own inputs are checked: shown as the worst
        return 3;
    }
    return 3;
}

/// The updates of one step combined: the worst status, the largest violations.
void combine(UpdateResult& step, const UpdateResult& result)
{
    if (severity(result.status) > severity(step.status)) step.status = result.status;
    step.lengthViolation = std::max(step.lengthViolation, result.lengthViolation);
    step.angleViolation = std::max(step.angleViolation, result.angleViolation);
    step.movedPoints += result.movedPoints;
}

/// A hose's attachment and whether a motion carries its node.
struct AttachmentLink
{
    int id = -1; ///< Hose::Attachment::id
    std::string sceneId;
    int node = -1;
    Frame offset;
};

/// A project collider (project.colliders) as the runtime holds it: one shared MeshCollider.
struct LiveCollider
{
    std::string sceneId;
    int node = -1;
    std::string path;
    std::shared_ptr<MeshCollider> collider;
    bool carried = false;
};

/// What one hose-object pair measures at the current step.
struct PairState
{
    double distance = kInfinity; ///< infinity: beyond the search distance
    int axisPoint = -1;
    Vec3 onHose = Vec3::Zero();
    Vec3 onObject = Vec3::Zero();
};

/// Everything kept per hose while sweeping.
struct SweptHose
{
    std::vector<AttachmentLink> attachments;
    std::vector<int> movedIds; ///< ids of the attachments on carried nodes
    std::vector<size_t> movedLinks;
    std::vector<const MeshCollider*> colliders; ///< the project colliders it stays outside
    std::vector<char> exempt;                   ///< per scene object
    std::vector<PairState> pairs;               ///< per scene object
    std::vector<int> slot;                      ///< per scene object: index in HoseSweep::objects
    std::uint64_t measuredRevision = 0;
};

void validate(const SweepOptions& options)
{
    if (options.steps < 1 || options.steps > 100000)
        throw InvalidArgument("sweep steps: expected 1 … 100000 steps each way, got " +
                              std::to_string(options.steps));
    if (!(options.clearanceThreshold >= 0.0) || !std::isfinite(options.clearanceThreshold))
        throw InvalidArgument("sweep clearance threshold: expected a finite distance >= 0 metres, "
                              "got " +
                              std::to_string(options.clearanceThreshold));
    if (!(options.reportDistance >= 0.0) || !std::isfinite(options.reportDistance))
        throw InvalidArgument(
            "sweep report distance: expected a finite distance >= 0 metres, got " +
            std::to_string(options.reportDistance));
    if (options.gravityStepsPerStep < 0 || options.gravityStepsPerStep > 100000)
        throw InvalidArgument("sweep gravity steps: expected 0 … 100000 a step, got " +
                              std::to_string(options.gravityStepsPerStep));
}

/// Records step `step`'s state of `hose` into `out`.
void measureStep(int step, const Hose& hose, const UpdateResult& update, HoseSweep& out)
{
    double stretch = 0.0;
    int stretchSegment = -1;
    for (int s = 0; s < hose.segmentCount(); ++s) {
        const double deviation =
            std::abs((hose.point(s + 1) - hose.point(s)).norm() / hose.restLength(s) - 1.0);
        if (deviation > stretch || stretchSegment < 0) stretch = deviation, stretchSegment = s;
    }
    out.stretchSeries.push_back(stretch);
    if (stretch > out.worstStretch || out.worstStretchStep < 0) {
        out.worstStretch = stretch;
        out.worstStretchStep = step;
        out.worstStretchSegment = stretchSegment;
    }
    const HoseMetrics metrics = measure(hose);
    // What the library guarantees after an update (lib/README.md): lengths and bends to 1e-9,
    // with colliders to their constraint tolerance after contact rounds.
    const double tolerance =
        std::max(kViolationTolerance,
                 hose.colliders().empty() ? 0.0 : hose.collisionOptions().constraintTolerance);
    if (metrics.lengthViolation > tolerance) {
        if (out.overstretchedSteps++ == 0) out.firstOverstretchedStep = step;
    }
    const bool straight = metrics.smallestBendRadiusJoint < 0 ||
                          metrics.smallestBendRadius >= std::numeric_limits<double>::max();
    const double radius = straight ? kInfinity : metrics.smallestBendRadius;
    out.bendRadiusSeries.push_back(radius);
    if (radius < out.smallestBendRadius) {
        out.smallestBendRadius = radius;
        out.smallestBendRadiusStep = step;
        out.smallestBendRadiusJoint = metrics.smallestBendRadiusJoint;
    }
    // The bend limit is a joint's deflection limit (for a minimum bend radius, the angle it
    // gives at the rest segment length): a segment compressed within its band shows a radius
    // below the minimum by that much without breaking the limit.
    if (metrics.angleViolation > tolerance) {
        if (out.bendViolationSteps++ == 0) out.firstBendViolationStep = step;
    }
    double gap = 0.0;
    for (const HoseMetrics::UnmetAttachment& unmet : metrics.unmetAttachments)
        gap = std::max(gap, unmet.gap);
    if (!metrics.unmetAttachments.empty()) {
        if (out.unmetSteps++ == 0) out.firstUnmetStep = step;
        if (gap > out.worstAttachmentGap) {
            out.worstAttachmentGap = gap;
            out.worstAttachmentGapStep = step;
        }
    }
    if (update.status != Status::Ok)
        out.updates.push_back(
            {step, update.status, update.lengthViolation, update.angleViolation, gap});
}

} // namespace

const char* toString(SweepStep::Phase phase)
{
    switch (phase) {
    case SweepStep::Phase::ProjectPose:
        return "project pose";
    case SweepStep::Phase::LeadIn:
        return "lead-in";
    case SweepStep::Phase::Out:
        return "out";
    case SweepStep::Phase::Back:
        return "back";
    }
    return "?";
}

std::vector<SweepStep> sweepSchedule(const std::vector<formats::PartMotion>& motions, int steps)
{
    if (steps < 1)
        throw InvalidArgument("sweep steps: expected at least 1 step each way, got " +
                              std::to_string(steps));
    if (motions.empty()) throw InvalidArgument("sweep: the project has no motions");
    // The lead-in: no step larger than a sweep step, for any motion.
    double leadInFraction = 0.0;
    for (const formats::PartMotion& motion : motions)
        leadInFraction =
            std::max(leadInFraction, -motion.minimum / (motion.maximum - motion.minimum));
    const int leadIn = static_cast<int>(std::ceil(steps * leadInFraction - 1e-9));
    std::vector<SweepStep> schedule;
    schedule.reserve(1 + static_cast<size_t>(leadIn) + 2 * static_cast<size_t>(steps));
    SweepStep start;
    start.values.assign(motions.size(), 0.0);
    if (leadIn == 0) start.t = 0.0;
    schedule.push_back(start);
    for (int k = 1; k <= leadIn; ++k) {
        SweepStep step;
        step.phase = SweepStep::Phase::LeadIn;
        for (const formats::PartMotion& motion : motions)
            step.values.push_back(k == leadIn ? motion.minimum : motion.minimum * k / leadIn);
        if (k == leadIn) step.t = 0.0;
        schedule.push_back(step);
    }
    const auto onPath = [&](SweepStep::Phase phase, int j) {
        SweepStep step;
        step.phase = phase;
        step.t = static_cast<double>(j) / steps;
        for (const formats::PartMotion& motion : motions)
            step.values.push_back(j == steps ? motion.maximum
                                             : formats::motionValueAt(motion, *step.t));
        schedule.push_back(step);
    };
    for (int j = 1; j <= steps; ++j)
        onPath(SweepStep::Phase::Out, j);
    for (int j = steps - 1; j >= 0; --j)
        onPath(SweepStep::Phase::Back, j);
    return schedule;
}

SweepReport sweepMotions(const formats::Project& project, const formats::ImportedScenes& scenes,
                         const SweepOptions& options)
{
    validate(options);
    SweepReport report;
    report.motions = project.motions;
    report.stepsEachWay = options.steps;
    report.clearanceThreshold = options.clearanceThreshold;
    report.reportDistance = std::max(options.reportDistance, options.clearanceThreshold);
    if (project.motions.empty() && !options.measurePoseWithoutMotions) return report;
    report.steps = project.motions.empty() ? std::vector<SweepStep>(1)
                                           : sweepSchedule(project.motions, options.steps);
    for (const SweepStep& step : report.steps)
        report.leadInSteps += step.phase == SweepStep::Phase::LeadIn;

    const formats::PartMotions motions(project, scenes);
    formats::ImportedScenes current = motions.posed();
    const auto worldFrameOf = [&](const std::string& sceneId, int node) {
        return current.at(sceneId).worldFrame(node);
    };

    // Scene objects for the clearance (sceneObjects: the project's pose), and the project's
    // colliders, which the hoses stay outside as in the runtime.
    std::vector<SceneObject> objects = sceneObjects(project, scenes);
    std::vector<char> objectCarried(objects.size(), 0);
    for (size_t o = 0; o < objects.size(); ++o)
        objectCarried[o] = motions.carried(objects[o].sceneId, objects[o].node);
    std::vector<LiveCollider> colliders;
    for (const formats::ColliderNode& flagged : project.colliders) {
        const auto scene = motions.posed().find(flagged.scene);
        if (scene == motions.posed().end()) continue;
        const int node = scene->second.findNode(flagged.node);
        if (node < 0)
            continue; // as formats::settleUnderGravity: an unknown node collides with nothing
        std::shared_ptr<MeshCollider> mesh =
            formats::nodeCollider(scene->second, node, scene->second.worldTransform(node));
        if (mesh)
            colliders.push_back({flagged.scene, node, flagged.node, std::move(mesh),
                                 motions.carried(flagged.scene, node)});
    }

    const double progressTotal = static_cast<double>(project.hoses.size() + report.steps.size());
    double progressDone = 0.0;
    const auto advance = [&](double amount) {
        progressDone += amount;
        if (options.progress && !options.progress(std::min(1.0, progressDone / progressTotal)))
            throw formats::Cancelled("motion sweep");
    };

    // The hoses as the clearance check and the export build them, then as the runtime holds
    // them: the project's colliders minus the exempt ones.
    std::vector<Hose> hoses;
    std::vector<SweptHose> swept(project.hoses.size());
    std::vector<UpdateResult> built(project.hoses.size());
    hoses.reserve(project.hoses.size());
    for (size_t h = 0; h < project.hoses.size(); ++h) {
        const formats::HoseDefinition& definition = project.hoses[h];
        hoses.push_back(formats::buildHose(project, definition, scenes, &built[h]));
        Hose& hose = hoses.back();
        formats::settleUnderGravity(hose, definition, project, scenes);
        SweptHose& state = swept[h];
        std::vector<std::shared_ptr<const MeshCollider>> used;
        for (const LiveCollider& collider : colliders)
            if (!formats::attachmentsExempt(definition, collider.sceneId, collider.path)) {
                used.push_back(collider.collider);
                state.colliders.push_back(collider.collider.get());
            }
        if (!used.empty()) hose.setColliders(std::move(used));
        for (size_t a = 0; a < definition.attachments.size(); ++a) {
            const formats::HoseAttachment& attachment = definition.attachments[a];
            AttachmentLink link;
            link.id = hose.attachments()[a].id;
            link.sceneId = attachment.scene;
            link.node = motions.posed().at(attachment.scene).findNode(attachment.node);
            link.offset = attachment.offset;
            link.offset.rotation.normalize();
            if (motions.carried(link.sceneId, link.node)) {
                state.movedIds.push_back(link.id);
                state.movedLinks.push_back(state.attachments.size());
            }
            state.attachments.push_back(std::move(link));
        }
        for (size_t c = 0; c < definition.clips.size(); ++c) { // after the attachments
            const formats::HoseClip& clip = definition.clips[c];
            AttachmentLink link;
            link.id = hose.attachments()[definition.attachments.size() + c].id;
            link.sceneId = clip.scene;
            link.node = motions.posed().at(clip.scene).findNode(clip.node);
            link.offset = clip.offset;
            link.offset.rotation.normalize();
            if (motions.carried(link.sceneId, link.node)) {
                state.movedIds.push_back(link.id);
                state.movedLinks.push_back(state.attachments.size());
            }
            state.attachments.push_back(std::move(link));
        }
        state.exempt.resize(objects.size());
        for (size_t o = 0; o < objects.size(); ++o)
            state.exempt[o] =
                !options.includeAttachedNodes &&
                formats::attachmentsExempt(definition, objects[o].sceneId, objects[o].path);
        state.pairs.resize(objects.size());
        state.slot.assign(objects.size(), -1);

        HoseSweep& result = report.hoses.emplace_back();
        result.hose = static_cast<int>(h);
        result.hoseId = definition.id;
        result.driven = !state.movedIds.empty();
        result.stretchBand = hose.material().expansionCoefficient;
        if (hose.material().bendLimit.kind == BendLimit::Kind::MinBendRadius)
            result.minBendRadius = hose.material().bendLimit.value;
        advance(1.0);
    }

    const double search = report.reportDistance;
    for (size_t s = 0; s < report.steps.size(); ++s) {
        const int step = static_cast<int>(s);
        std::vector<char> colliderMoved(colliders.size(), 0);
        std::vector<UpdateResult> updates(hoses.size());
        if (step == 0) {
            updates = built; // the project's pose: the hoses as built
        } else {
            motions.apply(report.steps[s].values, current);
            for (size_t c = 0; c < colliders.size(); ++c)
                if (colliders[c].carried)
                    colliderMoved[c] = colliders[c].collider->setFrame(
                        worldFrameOf(colliders[c].sceneId, colliders[c].node));
            for (size_t o = 0; o < objects.size(); ++o)
                if (objectCarried[o])
                    objects[o].collider->setFrame(
                        worldFrameOf(objects[o].sceneId, objects[o].node));
            for (size_t h = 0; h < hoses.size(); ++h) {
                Hose& hose = hoses[h];
                SweptHose& state = swept[h];
                if (!state.movedIds.empty()) {
                    std::vector<Frame> frames;
                    frames.reserve(state.movedLinks.size());
                    for (const size_t link : state.movedLinks) {
                        const AttachmentLink& a = state.attachments[link];
                        frames.push_back(worldFrameOf(a.sceneId, a.node) * a.offset);
                    }
                    combine(updates[h], hose.moveAttachments(state.movedIds, frames));
                } else {
                    bool pushed = false;
                    for (size_t c = 0; c < colliders.size() && !pushed; ++c)
                        pushed = colliderMoved[c] &&
                                 std::find(state.colliders.begin(), state.colliders.end(),
                                           colliders[c].collider.get()) != state.colliders.end();
                    if (pushed) combine(updates[h], hose.resolveCollisions());
                }
                if (hose.spec().gravity.enabled)
                    for (int g = 0; g < options.gravityStepsPerStep; ++g) {
                        const UpdateResult fall = hose.step();
                        combine(updates[h], fall);
                        if (fall.movedPoints == 0) break;
                    }
            }
        }
        for (size_t h = 0; h < hoses.size(); ++h) {
            const Hose& hose = hoses[h];
            SweptHose& state = swept[h];
            HoseSweep& result = report.hoses[h];
            measureStep(step, hose, updates[h], result);
            // Clearance: each pair measured again only when the hose or the object moved.
            const bool hoseMoved = step == 0 || hose.revision() != state.measuredRevision;
            state.measuredRevision = hose.revision();
            Aabb hoseBox;
            for (int i = 0; i < hose.pointCount(); ++i)
                hoseBox.extend(hose.point(i));
            hoseBox.min.array() -= search + hose.outerRadius();
            hoseBox.max.array() += search + hose.outerRadius();
            double nearest = kInfinity;
            for (size_t o = 0; o < objects.size(); ++o) {
                if (state.exempt[o]) continue;
                PairState& pair = state.pairs[o];
                if (hoseMoved || (step > 0 && objectCarried[o])) {
                    pair = PairState();
                    const Aabb box = objects[o].collider->worldBounds();
                    const bool apart = (box.min.array() > hoseBox.max.array()).any() ||
                                       (box.max.array() < hoseBox.min.array()).any();
                    if (!apart) {
                        const Clearance c = clearance(hose, *objects[o].collider, search);
                        if (c.found && c.distance < search) {
                            pair.distance = c.distance;
                            pair.axisPoint = c.axisPoint;
                            pair.onHose = c.onSurface;
                            pair.onObject = c.onObject;
                        }
                    }
                }
                if (!(pair.distance < kInfinity)) continue;
                nearest = std::min(nearest, pair.distance);
                if (state.slot[o] < 0) {
                    state.slot[o] = static_cast<int>(result.objects.size());
                    ObjectSweep listed;
                    listed.object = static_cast<int>(o);
                    listed.sceneId = objects[o].sceneId;
                    listed.objectPath = objects[o].path;
                    result.objects.push_back(std::move(listed));
                }
                ObjectSweep& listed = result.objects[static_cast<size_t>(state.slot[o])];
                if (pair.distance < listed.minDistance) {
                    listed.minDistance = pair.distance;
                    listed.step = step;
                    listed.axisPoint = pair.axisPoint;
                    listed.onHose = pair.onHose;
                    listed.onObject = pair.onObject;
                }
                if (pair.distance < options.clearanceThreshold) {
                    if (listed.stepsBelowThreshold++ == 0) listed.firstStepBelowThreshold = step;
                    listed.lastStepBelowThreshold = step;
                }
            }
            result.clearanceSeries.push_back(nearest);
        }
        if (options.onStep) options.onStep(step, hoses);
        advance(1.0);
    }
    for (HoseSweep& result : report.hoses)
        std::stable_sort(result.objects.begin(), result.objects.end(),
                         [](const ObjectSweep& a, const ObjectSweep& b) {
                             return a.minDistance < b.minDistance;
                         });
    return report;
}

SweepReport sweepProject(const std::filesystem::path& projectFile, const formats::NamedRoots& roots,
                         const SweepOptions& options)
{
    validate(options);
    formats::ProjectLoadOptions load;
    load.roots = roots;
    const formats::Project project = formats::loadProject(projectFile, load);
    if (project.motions.empty() && !options.measurePoseWithoutMotions)
        return sweepMotions(project, {}, options);
    const formats::ImportedScenes scenes =
        formats::importProjectScenes(project, projectFile, roots);
    return sweepMotions(project, scenes, options);
}

std::string sweepReportJson(const SweepReport& report, const std::string& projectFile)
{
    using ordered = nlohmann::ordered_json;
    const auto number = [](double value) -> ordered {
        if (!std::isfinite(value)) return nullptr;
        return value;
    };
    const auto stepIndex = [](int step) -> ordered {
        if (step < 0) return nullptr;
        return step;
    };
    const auto vec3 = [](const Vec3& v) { return ordered::array({v.x(), v.y(), v.z()}); };
    const auto series = [&](const std::vector<double>& values) {
        ordered out = ordered::array();
        for (const double value : values)
            out.push_back(number(value));
        return out;
    };

    ordered document = ordered::object();
    document["project"] = projectFile;
    document["violations"] = report.violations();
    document["stepsEachWay"] = report.stepsEachWay;
    document["leadInSteps"] = report.leadInSteps;
    document["clearanceThreshold"] = report.clearanceThreshold;
    document["reportDistance"] = report.reportDistance;
    ordered motions = ordered::array();
    for (const formats::PartMotion& motion : report.motions) {
        const bool hinge = motion.kind == formats::PartMotion::Kind::Hinge;
        motions.push_back(ordered{{"id", motion.id},
                                  {"scene", motion.scene},
                                  {"node", motion.node},
                                  {"kind", formats::toString(motion.kind)},
                                  {"unit", hinge ? "rad" : "m"},
                                  {"min", motion.minimum},
                                  {"max", motion.maximum}});
    }
    document["motions"] = motions;
    ordered steps = ordered::array();
    for (const SweepStep& step : report.steps) {
        ordered values = ordered::array();
        for (const double value : step.values)
            values.push_back(value);
        steps.push_back(ordered{{"phase", toString(step.phase)},
                                {"t", step.t ? ordered(*step.t) : ordered(nullptr)},
                                {"values", values}});
    }
    document["steps"] = steps;
    ordered hoses = ordered::array();
    for (const HoseSweep& hose : report.hoses) {
        ordered entry = ordered::object();
        entry["id"] = hose.hoseId;
        entry["driven"] = hose.driven;
        entry["violates"] = hose.violates();
        entry["stretch"] =
            ordered{{"band", hose.stretchBand},
                    {"worst", hose.worstStretch},
                    {"step", stepIndex(hose.worstStretchStep)},
                    {"segment", stepIndex(hose.worstStretchSegment)},
                    {"overstretchedSteps", hose.overstretchedSteps},
                    {"firstOverstretchedStep", stepIndex(hose.firstOverstretchedStep)}};
        entry["bend"] = ordered{{"minimumRadius", hose.minBendRadius},
                                {"smallestRadius", number(hose.smallestBendRadius)},
                                {"step", stepIndex(hose.smallestBendRadiusStep)},
                                {"joint", stepIndex(hose.smallestBendRadiusJoint)},
                                {"violationSteps", hose.bendViolationSteps},
                                {"firstViolationStep", stepIndex(hose.firstBendViolationStep)}};
        entry["reach"] = ordered{{"worstGap", hose.worstAttachmentGap},
                                 {"step", stepIndex(hose.worstAttachmentGapStep)},
                                 {"unmetSteps", hose.unmetSteps},
                                 {"firstUnmetStep", stepIndex(hose.firstUnmetStep)}};
        ordered objects = ordered::array();
        for (const ObjectSweep& object : hose.objects)
            objects.push_back(
                ordered{{"scene", object.sceneId},
                        {"path", object.objectPath},
                        {"minDistance", object.minDistance},
                        {"step", object.step},
                        {"axisPoint", object.axisPoint},
                        {"onHose", vec3(object.onHose)},
                        {"onObject", vec3(object.onObject)},
                        {"collides", object.collides()},
                        {"stepsBelowThreshold", object.stepsBelowThreshold},
                        {"firstStepBelowThreshold", stepIndex(object.firstStepBelowThreshold)},
                        {"lastStepBelowThreshold", stepIndex(object.lastStepBelowThreshold)}});
        entry["objects"] = objects;
        ordered updates = ordered::array();
        for (const SweepUpdate& update : hose.updates)
            updates.push_back(ordered{{"step", update.step},
                                      {"status", chaintube::toString(update.status)},
                                      {"lengthViolation", update.lengthViolation},
                                      {"angleViolation", update.angleViolation},
                                      {"attachmentGap", update.attachmentGap}});
        entry["updates"] = updates;
        entry["series"] = ordered{{"stretch", series(hose.stretchSeries)},
                                  {"bendRadius", series(hose.bendRadiusSeries)},
                                  {"clearance", series(hose.clearanceSeries)}};
        hoses.push_back(entry);
    }
    document["hoses"] = hoses;
    return document.dump(2) + "\n";
}

} // namespace chaintube::exporting
