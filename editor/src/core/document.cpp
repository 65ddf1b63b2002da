#include "chaintube/editor/document.h"

#include "chaintube/editor/commands.h"
#include "chaintube/formats/collider_exemption.h"
#include "chaintube/route.h"

#include <QMetaType>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>

namespace chaintube::editor {

namespace fs = std::filesystem;

LoadedProject readProject(const fs::path& file, const formats::NamedRoots& roots,
                          const std::function<bool(double)>& progress,
                          const std::optional<std::string>& textOverride)
{
    LoadedProject loaded;
    formats::ProjectLoadOptions options;
    options.roots = roots;
    loaded.project = textOverride ? formats::parseProject(*textOverride, file, options)
                                  : formats::loadProject(file, options);
    loaded.file = file;
    // Scenes that cannot be found are left out and named, so that the project still opens.
    formats::Project present = loaded.project;
    present.scenes.clear();
    for (const formats::SceneReference& reference : loaded.project.scenes) {
        try {
            const fs::path sceneFile = formats::resolveScenePath(reference, file, roots);
            std::error_code error;
            if (fs::exists(sceneFile, error))
                present.scenes.push_back(reference);
            else
                loaded.missingScenes[reference.id] =
                    reference.path + ": no such file (" + sceneFile.string() + ")";
        } catch (const formats::PathError& error) {
            loaded.missingScenes[reference.id] = error.what();
        }
    }
    loaded.scenes = formats::importProjectScenes(present, file, roots, progress);
    // A saved pose must name a node the scene still has (the scene file may have changed).
    for (size_t i = 0; i < loaded.project.poses.size(); ++i) {
        const formats::NodePose& pose = loaded.project.poses[i];
        if (loaded.missingScenes.count(pose.scene)) continue; // checked when it is located
        const auto imported = loaded.scenes.find(pose.scene);
        if (imported == loaded.scenes.end() || imported->second.findNode(pose.node) < 0)
            throw formats::ProjectFormatError(file, "/poses/" + std::to_string(i) + "/node",
                                              "expected a node of scene '" + pose.scene + "' (" +
                                                  (imported == loaded.scenes.end()
                                                       ? std::string("not imported")
                                                       : imported->second.file.string()) +
                                                  "), got \"" + pose.node + "\"");
    }
    return loaded;
}

Document::Document(formats::NamedRoots roots, QObject* parent)
    : QObject(parent), m_roots(std::move(roots))
{
    qRegisterMetaType<ChangeEvent>();
    m_project = formats::Project::withStandardPresets("Untitled");
    connect(&m_undoStack, &QUndoStack::cleanChanged, this,
            [this](bool) { emitChanged(ChangeEvent::Kind::FileStateChanged); });
    // An edit ends a motion preview: the project's pose is what edits apply to.
    connect(&m_undoStack, &QUndoStack::indexChanged, this, [this](int) { clearMotionPreview(); });
}

Document::~Document()
{
    // Nobody may hear about the undo stack's destruction (its commands refer to us).
    blockSignals(true);
    m_undoStack.disconnect(this);
    m_undoStack.clear();
}

void Document::adopt(LoadedProject loaded)
{
    m_undoStack.clear();
    const bool previewed = !m_motionValues.empty();
    dropMotionPreview();
    m_project = std::move(loaded.project);
    m_file = std::move(loaded.file);
    m_scenes = std::move(loaded.scenes);
    m_missingScenes = std::move(loaded.missingScenes);
    m_pose.clear();
    for (const formats::NodePose& pose : m_project.poses) {
        const formats::ImportedScene* imported = scene(pose.scene);
        const int node = imported ? imported->findNode(pose.node) : -1;
        if (node >= 0) // readProject checked; an untitled project has none
            m_pose[{pose.scene, node}] = pose.localTransform;
    }
    ++m_poseSerial;
    m_selection = {};
    m_forcedModified = false;
    rebuildAllHoses();
    m_undoStack.setClean();
    emitChanged(ChangeEvent::Kind::ProjectReplaced);
    emitChanged(ChangeEvent::Kind::FileStateChanged);
    if (previewed) emit motionPreviewChanged();
}

void Document::reset(const std::string& projectName)
{
    LoadedProject empty;
    empty.project = formats::Project::withStandardPresets(projectName);
    adopt(std::move(empty));
}

void Document::save(const fs::path& file)
{
    // The file reproduces the settled sag, not a half-way frame: show that before writing.
    settleGravity();
    formats::ProjectLoadOptions validation;
    validation.roots = m_roots;
    // Into another folder (Save As): every path the project holds is re-expressed from there.
    formats::Project saved =
        m_file.empty() ? m_project : formats::rebaseProject(m_project, m_file, file);
    formats::saveProject(saved, file, validation);
    m_project = std::move(saved);
    m_file = file;
    m_forcedModified = false;
    m_undoStack.setClean();
    emitChanged(ChangeEvent::Kind::FileStateChanged);
}

void Document::setForcedModified(bool modified)
{
    m_forcedModified = modified;
    emitChanged(ChangeEvent::Kind::FileStateChanged);
}

const formats::ImportedScene* Document::scene(const std::string& sceneId) const
{
    const auto it = m_scenes.find(sceneId);
    return it == m_scenes.end() ? nullptr : &it->second;
}

int Document::hoseIndex(const std::string& hoseId) const
{
    for (size_t i = 0; i < m_project.hoses.size(); ++i)
        if (m_project.hoses[i].id == hoseId) return static_cast<int>(i);
    return -1;
}

const formats::HoseDefinition* Document::hoseDefinition(const std::string& hoseId) const
{
    const int index = hoseIndex(hoseId);
    return index < 0 ? nullptr : &m_project.hoses[static_cast<size_t>(index)];
}

formats::HoseDefinition* Document::mutableHoseDefinition(const std::string& hoseId)
{
    const int index = hoseIndex(hoseId);
    return index < 0 ? nullptr : &m_project.hoses[static_cast<size_t>(index)];
}

const Hose* Document::hose(const std::string& hoseId) const
{
    const auto it = m_live.find(hoseId);
    return it == m_live.end() || !it->second.hose ? nullptr : &*it->second.hose;
}

std::string Document::hoseBuildError(const std::string& hoseId) const
{
    const auto it = m_live.find(hoseId);
    return it == m_live.end() ? std::string() : it->second.error;
}

std::uint64_t Document::hoseBuildSerial(const std::string& hoseId) const
{
    const auto it = m_live.find(hoseId);
    return it == m_live.end() ? 0 : it->second.buildSerial;
}

const HoseMetrics* Document::hoseMetrics(const std::string& hoseId) const
{
    const auto it = m_live.find(hoseId);
    if (it == m_live.end() || !it->second.hose) return nullptr;
    const LiveHose& live = it->second;
    const std::uint64_t revision = live.hose->revision() ^ (live.buildSerial << 40);
    if (!live.metrics || live.metricsRevision != revision) {
        live.metrics = measure(*live.hose);
        live.metricsRevision = revision;
    }
    return &*live.metrics;
}

UpdateResult Document::lastUpdate(const std::string& hoseId) const
{
    const auto it = m_live.find(hoseId);
    return it == m_live.end() ? UpdateResult() : it->second.lastUpdate;
}

std::string Document::validateHoseDefinition(const formats::HoseDefinition& definition) const
{
    try {
        if (!(definition.outerDiameter > 0.0) || !std::isfinite(definition.outerDiameter))
            return "The outer diameter must be a positive number of metres.";
        if (definition.route.size() < 2) return "A hose needs at least two route points.";
        formats::hoseSpecOf(m_project, definition).validate();
        // Builds it as rebuildHose() would (attachment ranges, length, poses).
        static_cast<void>(formats::buildHose(m_project, definition, m_scenes));
    } catch (const std::exception& error) {
        return error.what();
    }
    return {};
}

std::string Document::unusedHoseId() const
{
    for (int n = 1;; ++n) {
        std::string id = "hose-" + std::to_string(n);
        if (hoseIndex(id) < 0) return id;
    }
}

std::string Document::unusedSocketId() const
{
    for (int n = 1;; ++n) {
        std::string id = "socket-" + std::to_string(n);
        if (!m_project.findSocket(id)) return id;
    }
}

std::string Document::validateSocket(const formats::Socket& socket)
{
    if (!socket.position.allFinite()) return "the socket's position must be finite";
    if (!socket.axis.allFinite() || !(socket.axis.norm() > 1e-9))
        return "the socket's axis must be a non-zero direction";
    if (!std::isfinite(socket.captureRadius) || !(socket.captureRadius > 0.0))
        return "the capture radius must be a length > 0 m";
    if (!std::isfinite(socket.captureAngle) || !(socket.captureAngle > 0.0) ||
        socket.captureAngle > std::numbers::pi)
        return "the capture angle must lie in (0°, 180°]";
    if (socket.tag.empty()) return "the tag must not be empty (it says which plugs fit)";
    return {};
}

bool Document::socketWorld(const formats::Socket& socket, Vec3* position, Vec3* axis) const
{
    const formats::ImportedScene* imported = scene(socket.scene);
    const int node = imported ? imported->findNode(socket.node) : -1;
    if (node < 0) return false;
    const Frame frame = nodeWorldFrame(socket.scene, node);
    if (position) *position = frame.apply(socket.position);
    if (axis) *axis = (frame.rotation * socket.axis).normalized();
    return true;
}

void Document::socketsChanged()
{
    emitChanged(ChangeEvent::Kind::SocketsChanged);
    if (!m_selection.socketId.empty() && !m_project.findSocket(m_selection.socketId)) {
        Selection selection = m_selection;
        selection.socketId.clear();
        setSelection(selection);
    }
}

formats::Mat4 Document::nodeLocalTransform(const std::string& sceneId, int node) const
{
    if (!m_motionLocal.empty()) {
        const auto previewed = m_motionLocal.find({sceneId, node});
        if (previewed != m_motionLocal.end()) return previewed->second;
    }
    const auto it = m_pose.find({sceneId, node});
    if (it != m_pose.end() && it->second) return *it->second;
    const formats::ImportedScene* imported = scene(sceneId);
    if (!imported || node < 0 || node >= static_cast<int>(imported->nodes.size()))
        return formats::Mat4::Identity();
    return imported->nodes[static_cast<size_t>(node)].localTransform;
}

formats::Mat4 Document::nodeWorldTransform(const std::string& sceneId, int node) const
{
    const formats::ImportedScene* imported = scene(sceneId);
    if (!imported || node < 0 || node >= static_cast<int>(imported->nodes.size()))
        return formats::Mat4::Identity();
    formats::Mat4 world = formats::Mat4::Identity();
    for (int n = node; n >= 0; n = imported->nodes[static_cast<size_t>(n)].parent)
        world = nodeLocalTransform(sceneId, n) * world;
    return world;
}

void Document::setClearanceMarkers(std::vector<ClearanceMarker> markers)
{
    const auto same = [](const ClearanceMarker& a, const ClearanceMarker& b) {
        return a.hoseId == b.hoseId && a.axisPoint == b.axisPoint && a.onHose == b.onHose &&
               a.onObject == b.onObject;
    };
    if (markers.size() == m_clearanceMarkers.size() &&
        std::equal(markers.begin(), markers.end(), m_clearanceMarkers.begin(), same))
        return;
    m_clearanceMarkers = std::move(markers);
    emit clearanceMarkersChanged();
}

Frame Document::nodeWorldFrame(const std::string& sceneId, int node) const
{
    return rigidPart(nodeWorldTransform(sceneId, node));
}

Frame Document::filePoseWorldFrame(const std::string& sceneId, int node) const
{
    const formats::ImportedScene* imported = scene(sceneId);
    if (!imported || node < 0 || node >= static_cast<int>(imported->nodes.size()))
        return Frame::identity();
    formats::Mat4 world = formats::Mat4::Identity();
    for (int n = node; n >= 0; n = imported->nodes[static_cast<size_t>(n)].parent)
        world = imported->nodes[static_cast<size_t>(n)].localTransform * world;
    return rigidPart(world);
}

Vec3 Document::partCentre(const std::string& sceneId, int node) const
{
    const formats::ImportedScene* imported = scene(sceneId);
    if (!imported || node < 0 || node >= static_cast<int>(imported->nodes.size()))
        return Vec3::Zero();
    Vec3 low = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 high = -low;
    std::vector<int> pending{node};
    while (!pending.empty()) {
        const int n = pending.back();
        pending.pop_back();
        const formats::SceneNode& sceneNode = imported->nodes[static_cast<size_t>(n)];
        pending.insert(pending.end(), sceneNode.children.begin(), sceneNode.children.end());
        if (sceneNode.meshes.empty()) continue;
        const formats::Mat4 world = nodeWorldTransform(sceneId, n);
        for (int meshIndex : sceneNode.meshes) {
            const formats::SceneMesh& mesh = imported->meshes[static_cast<size_t>(meshIndex)];
            auto bounds = m_meshBounds.find(&mesh);
            if (bounds == m_meshBounds.end()) {
                Vec3 meshLow = Vec3::Constant(std::numeric_limits<double>::infinity());
                Vec3 meshHigh = -meshLow;
                for (size_t v = 0; v < mesh.vertexCount(); ++v) {
                    const Vec3 p(mesh.positions[3 * v], mesh.positions[3 * v + 1],
                                 mesh.positions[3 * v + 2]);
                    meshLow = meshLow.cwiseMin(p);
                    meshHigh = meshHigh.cwiseMax(p);
                }
                bounds = m_meshBounds.emplace(&mesh, std::make_pair(meshLow, meshHigh)).first;
            }
            const auto& [meshLow, meshHigh] = bounds->second;
            if (!(meshLow.array() <= meshHigh.array()).all()) continue; // no vertices
            for (int corner = 0; corner < 8; ++corner) {
                const Vec3 local((corner & 1) ? meshHigh.x() : meshLow.x(),
                                 (corner & 2) ? meshHigh.y() : meshLow.y(),
                                 (corner & 4) ? meshHigh.z() : meshLow.z());
                const Vec3 p = (world * local.homogeneous()).head<3>();
                low = low.cwiseMin(p);
                high = high.cwiseMax(p);
            }
        }
    }
    if (!(low.array() <= high.array()).all()) return nodeWorldFrame(sceneId, node).translation;
    return 0.5 * (low + high);
}

bool Document::hoseFollowsMovedPart(const std::string& hoseId) const
{
    const formats::HoseDefinition* definition = hoseDefinition(hoseId);
    return definition && hoseAffectedByPose(*definition);
}

std::vector<Vec3> Document::displayRoute(const std::string& hoseId) const
{
    const formats::HoseDefinition* definition = hoseDefinition(hoseId);
    const Hose* live = hose(hoseId);
    if (!definition) return {};
    if (!live || !hoseAffectedByPose(*definition) || definition->attachments.empty())
        return definition->route;
    // Each attachment's motion (file pose → pose) and where it sits along the hose (0 … 1).
    struct Motion
    {
        double along;
        Frame motion;
    };
    std::vector<Motion> motions;
    const std::vector<Frame> posed = posedAttachmentFrames(*definition);
    for (size_t a = 0; a < definition->attachments.size(); ++a) {
        const formats::HoseAttachment& attachment = definition->attachments[a];
        const formats::ImportedScene* imported = scene(attachment.scene);
        const int node = imported ? imported->findNode(attachment.node) : -1;
        if (node < 0) return definition->route;
        Frame offset = attachment.offset;
        offset.rotation.normalize();
        const Frame filePose = imported->worldFrame(node) * offset;
        motions.push_back({0.5 * (attachment.firstPoint + attachment.lastPoint) /
                               std::max(1, live->segmentCount()),
                           posed[a] * filePose.inverse()});
    }
    std::sort(motions.begin(), motions.end(),
              [](const Motion& a, const Motion& b) { return a.along < b.along; });
    const std::vector<Vec3>& route = definition->route;
    const double total = std::max(1e-300, polylineLength(route));
    std::vector<Vec3> carried;
    double walked = 0.0;
    for (size_t i = 0; i < route.size(); ++i) {
        if (i > 0) walked += (route[i] - route[i - 1]).norm();
        const double along = walked / total;
        size_t next = 0;
        while (next < motions.size() && motions[next].along < along)
            ++next;
        if (next == 0) {
            carried.push_back(motions.front().motion.apply(route[i]));
        } else if (next == motions.size()) {
            carried.push_back(motions.back().motion.apply(route[i]));
        } else {
            const Motion& before = motions[next - 1];
            const Motion& after = motions[next];
            const double w = (along - before.along) / std::max(1e-12, after.along - before.along);
            carried.push_back((1.0 - w) * before.motion.apply(route[i]) +
                              w * after.motion.apply(route[i]));
        }
    }
    return carried;
}

void Document::setSelection(const Selection& selection)
{
    if (selection == m_selection) return;
    m_selection = selection;
    emitChanged(ChangeEvent::Kind::SelectionChanged, selection.hoseId);
}

UpdateResult Document::dragHosePoint(const std::string& hoseId, int point, const Vec3& target)
{
    const auto it = m_live.find(hoseId);
    if (it == m_live.end() || !it->second.hose) {
        UpdateResult invalid;
        invalid.status = Status::InvalidInput;
        return invalid;
    }
    Hose& hose = *it->second.hose;
    hose.setBudget(UpdateBudget::realtime());
    const UpdateResult result = hose.grab(point, target);
    if (result.status != Status::InvalidInput) {
        it->second.dragPoint = point;
        it->second.dragTarget = target;
    }
    if (result.movedPoints > 0) {
        wakeGravity(hoseId);
        emitChanged(ChangeEvent::Kind::HoseShapeChanged, hoseId);
    }
    return result;
}

UpdateResult Document::finishHoseDrag(const std::string& hoseId)
{
    UpdateResult result;
    const auto it = m_live.find(hoseId);
    if (it == m_live.end() || !it->second.hose) {
        result.status = Status::InvalidInput;
        return result;
    }
    Hose& hose = *it->second.hose;
    hose.setBudget(UpdateBudget{});
    const int point = it->second.dragPoint;
    const Vec3 target = it->second.dragTarget;
    it->second.dragPoint = -1;
    const UpdateResult pending = hose.finishPending();
    int moved = pending.movedPoints, iterations = pending.iterations;
    if (point >= 0) {
        result = hose.grab(point, target);
        moved = std::max(moved, result.movedPoints);
        iterations += result.iterations;
        for (int call = 1; call < kDragGrabs && result.status == Status::Clamped; ++call) {
            if (result.movedPoints == 0) {
                // No nearer in one go: the rest of the way in short steps (a path of small moves
                // reaches where one long step stops at the bend limits), then the target again.
                const Vec3 from = hose.point(point);
                const double way = (target - from).norm();
                const int steps =
                    std::min(kDragSubSteps, static_cast<int>(std::ceil(way / kDragSubStep)));
                int stepMoved = 0;
                for (int s = 1; s < steps; ++s) {
                    const UpdateResult r =
                        hose.grab(point, from + (target - from) * (double(s) / steps));
                    stepMoved = std::max(stepMoved, r.movedPoints);
                    iterations += r.iterations;
                }
                if (stepMoved == 0) break;
                moved = std::max(moved, stepMoved);
            }
            result = hose.grab(point, target);
            moved = std::max(moved, result.movedPoints);
            iterations += result.iterations;
        }
    } else {
        result = pending;
    }
    result.movedPoints = moved;
    result.iterations = iterations;
    if (result.movedPoints > 0) {
        wakeGravity(hoseId);
        emitChanged(ChangeEvent::Kind::HoseShapeChanged, hoseId);
    }
    return result;
}

bool Document::commitHoseDrag(const std::string& hoseId, int draggedPoint, std::string* why)
{
    if (!hoseDefinition(hoseId) || !hose(hoseId)) return false;
    static_cast<void>(finishHoseDrag(hoseId)); // the release converges fully
    const formats::HoseDefinition* definition = hoseDefinition(hoseId);
    const Hose* live = hose(hoseId);
    if (!definition || !live) return false;
    if (!m_motionValues.empty() && hoseAffectedByPose(*definition)) {
        if (why)
            *why = "This hose is fixed to a part the motion preview moves; reset the motions "
                   "before reshaping the hose (the route is stored at the project's pose).";
        rebuildHose(hoseId);
        emitChanged(ChangeEvent::Kind::HoseShapeChanged, hoseId);
        return false;
    }
    if (hoseAffectedByPose(*definition)) {
        if (why)
            *why = "This hose is fixed to a part that is moved from its file position; reset "
                   "the part's transform before reshaping the hose (the route is stored at "
                   "the file position).";
        rebuildHose(hoseId);
        emitChanged(ChangeEvent::Kind::HoseShapeChanged, hoseId);
        return false;
    }
    std::vector<Vec3> route = live->points();
    // Consecutive points can coincide after an extreme drag; a route needs distinct points.
    route.erase(std::unique(route.begin(), route.end(),
                            [](const Vec3& a, const Vec3& b) { return (a - b).norm() < 1e-9; }),
                route.end());
    formats::HoseDefinition changed = *definition;
    changed.route = route;
    // The shape changes, the length does not: a hose without a length of its own keeps the
    // one it had (the stretch of the drag is not taken as new hose).
    if (!changed.length) changed.length = live->restLengthTotal();
    const std::string problem = validateHoseDefinition(changed);
    if (!problem.empty()) {
        if (why) *why = problem;
        rebuildHose(hoseId);
        emitChanged(ChangeEvent::Kind::HoseShapeChanged, hoseId);
        return false;
    }
    const QString hoseName =
        QString::fromStdString(definition->name.empty() ? definition->id : definition->name);
    m_undoStack.push(makeSetHoseDefinition(
        *this, hoseId, std::move(changed), MergeId::None,
        draggedPoint >= 0 ? tr("Drag point %1 of %2").arg(draggedPoint).arg(hoseName)
                          : tr("Drag %1").arg(hoseName)));
    return true;
}

void Document::cancelHoseDrag(const std::string& hoseId)
{
    if (const auto it = m_live.find(hoseId); it != m_live.end()) it->second.dragPoint = -1;
    rebuildHose(hoseId);
    emitChanged(ChangeEvent::Kind::HoseShapeChanged, hoseId);
}

void Document::wakeGravity(const std::string& hoseId)
{
    const auto it = m_live.find(hoseId);
    if (it == m_live.end() || !it->second.hose || !it->second.hose->spec().gravity.enabled) return;
    it->second.gravitySettled = false;
    it->second.gravitySteps = 0;
    emit gravityStateChanged();
}

int Document::stepGravity()
{
    std::vector<std::string> moved;
    bool stateChanged = false;
    for (auto& [id, live] : m_live) {
        if (!live.hose || !live.hose->spec().gravity.enabled || live.gravitySettled ||
            live.gravitySteps >= kGravityStepBudget)
            continue;
        ++live.gravitySteps;
        if (live.hose->step().movedPoints > 0) {
            moved.push_back(id);
            stateChanged = stateChanged || live.gravitySteps >= kGravityStepBudget;
        } else {
            live.gravitySettled = true;
            stateChanged = true;
        }
    }
    for (const std::string& id : moved) // after the loop: listeners may read any hose
        emitChanged(ChangeEvent::Kind::HoseShapeChanged, id);
    if (stateChanged) emit gravityStateChanged();
    return static_cast<int>(moved.size());
}

int Document::advanceGravity(double seconds)
{
    if (!gravityActive()) {
        m_gravityOwed = 0.0;
        return 0;
    }
    if (std::isfinite(seconds) && seconds > 0.0)
        m_gravityOwed += std::min(seconds, Gravity::kMaxFrameSeconds);
    int calls = 0;
    // The tolerance takes a timer's 1/90 s, read back with rounding, for a whole step.
    while (m_gravityOwed >= Gravity::kFrameSeconds * (1.0 - 1e-6) && gravityActive()) {
        stepGravity();
        m_gravityOwed = std::max(0.0, m_gravityOwed - Gravity::kFrameSeconds);
        ++calls;
    }
    if (!gravityActive()) m_gravityOwed = 0.0;
    return calls;
}

bool Document::gravityActive() const
{
    for (const auto& [id, live] : m_live)
        if (live.hose && live.hose->spec().gravity.enabled && !live.gravitySettled &&
            live.gravitySteps < kGravityStepBudget)
            return true;
    return false;
}

int Document::settleGravity()
{
    int calls = 0;
    while (gravityActive()) {
        stepGravity();
        ++calls;
    }
    return calls;
}

std::vector<std::string> Document::gravityUnsettledHoses() const
{
    std::vector<std::string> unsettled;
    for (const formats::HoseDefinition& definition : m_project.hoses) {
        const auto it = m_live.find(definition.id);
        if (it != m_live.end() && it->second.hose && definition.gravity.enabled &&
            !it->second.gravitySettled && it->second.gravitySteps >= kGravityStepBudget)
            unsettled.push_back(definition.id);
    }
    return unsettled;
}

Document::GravityState Document::gravityState(const std::string& hoseId) const
{
    const auto it = m_live.find(hoseId);
    if (it == m_live.end() || !it->second.hose || !it->second.hose->spec().gravity.enabled)
        return GravityState::Off;
    if (it->second.gravitySettled) return GravityState::Settled;
    return it->second.gravitySteps >= kGravityStepBudget ? GravityState::OutOfBudget
                                                         : GravityState::Settling;
}

int Document::gravitySteps(const std::string& hoseId) const
{
    const auto it = m_live.find(hoseId);
    return it == m_live.end() ? 0 : it->second.gravitySteps;
}

bool Document::isCollider(const std::string& sceneId, int node) const
{
    const formats::ImportedScene* imported = scene(sceneId);
    if (!imported || node < 0 || node >= static_cast<int>(imported->nodes.size())) return false;
    const formats::ColliderNode key{sceneId, imported->nodes[static_cast<size_t>(node)].path};
    return std::find(m_project.colliders.begin(), m_project.colliders.end(), key) !=
           m_project.colliders.end();
}

std::vector<std::shared_ptr<const MeshCollider>>
Document::hoseColliders(const std::string& hoseId) const
{
    const Hose* live = hose(hoseId);
    return live ? live->colliders() : std::vector<std::shared_ptr<const MeshCollider>>();
}

void Document::rebuildColliders()
{
    m_colliders.clear();
    for (const formats::ColliderNode& flagged : m_project.colliders) {
        const formats::ImportedScene* imported = scene(flagged.scene);
        const int node = imported ? imported->findNode(flagged.node) : -1;
        if (node < 0) continue; // readProject checked; a removed scene takes its parts with it
        std::shared_ptr<MeshCollider> collider =
            formats::nodeCollider(*imported, node, nodeWorldTransform(flagged.scene, node));
        if (collider) // a part without triangles cannot collide (the export refuses it)
            m_colliders.push_back({flagged.scene, node, std::move(collider)});
    }
    for (const formats::HoseDefinition& definition : m_project.hoses)
        applyColliders(definition.id);
}

void Document::applyColliders(const std::string& hoseId)
{
    const formats::HoseDefinition* definition = hoseDefinition(hoseId);
    auto live = m_live.find(hoseId);
    if (!definition || live == m_live.end() || !live->second.hose) return;
    std::vector<std::shared_ptr<const MeshCollider>> used;
    std::vector<NodeKey> usedNodes;
    for (const LiveCollider& c : m_colliders) {
        const formats::ImportedScene* imported = scene(c.sceneId);
        if (!imported) continue;
        const auto parentOf = [&](int n) { return imported->nodes[static_cast<size_t>(n)].parent; };
        const bool exempt = std::any_of(
            definition->attachments.begin(), definition->attachments.end(),
            [&](const formats::HoseAttachment& a) {
                return a.scene == c.sceneId &&
                       formats::attachmentExempts(imported->findNode(a.node), c.node, parentOf);
            });
        if (!exempt) {
            used.push_back(c.collider);
            usedNodes.push_back({c.sceneId, c.node});
        }
    }
    live->second.colliderNodes = std::move(usedNodes);
    Hose& hoseObject = *live->second.hose;
    if (used == hoseObject.colliders()) return;
    hoseObject.setColliders(std::move(used));
    wakeGravity(hoseId); // a gravity hose settles again against what it now rests on
}

void Document::collidersChanged(const NodeKey& node)
{
    std::map<std::string, std::vector<NodeKey>> before;
    for (const auto& [id, live] : m_live)
        before[id] = live.colliderNodes;
    rebuildColliders();
    // A hose that now stays outside another set of parts is built again and pushed out of
    // them (as a collider moved into it pushes it); one the flag no longer concerns is built
    // as without it. Either way its shape is that of the document's state, so undoing the
    // flag gives back exactly the shape before it.
    std::vector<std::string> rebuilt;
    for (const auto& [id, live] : m_live)
        if (live.colliderNodes != before[id]) rebuilt.push_back(id);
    for (const std::string& id : rebuilt) {
        rebuildHose(id);
        emitChanged(ChangeEvent::Kind::HoseShapeChanged, id);
    }
    ChangeEvent event;
    event.kind = ChangeEvent::Kind::CollidersChanged;
    event.sceneId = node.first;
    event.node = node.second;
    emit changed(event);
}

std::string Document::stateFingerprint() const
{
    std::ostringstream out;
    out << formats::serialiseProject(m_project);
    out.precision(17);
    for (const auto& [key, transform] : m_pose) {
        if (!transform) continue;
        out << "pose " << key.first << ' ' << key.second;
        for (int i = 0; i < 16; ++i)
            out << ' ' << (*transform)(i % 4, i / 4);
        out << '\n';
    }
    for (const auto& [id, imported] : m_scenes)
        out << "scene " << id << ' ' << imported.nodes.size() << '\n';
    return out.str();
}

std::optional<formats::Mat4>* Document::mutablePoseOverride(const NodeKey& node)
{
    return &m_pose[node];
}

void Document::hoseDefinitionChanged(const std::string& hoseId)
{
    rebuildHose(hoseId);
    emitChanged(ChangeEvent::Kind::HoseChanged, hoseId);
}

void Document::insertHose(int index, formats::HoseDefinition definition)
{
    const std::string id = definition.id;
    index = std::clamp(index, 0, hoseCount());
    m_project.hoses.insert(m_project.hoses.begin() + index, std::move(definition));
    rebuildHose(id);
    emitChanged(ChangeEvent::Kind::HoseAdded, id);
}

formats::HoseDefinition Document::removeHose(const std::string& hoseId)
{
    const int index = hoseIndex(hoseId);
    formats::HoseDefinition removed = m_project.hoses.at(static_cast<size_t>(index));
    m_project.hoses.erase(m_project.hoses.begin() + index);
    m_live.erase(hoseId);
    if (m_selection.hoseId == hoseId) {
        Selection cleared = m_selection;
        cleared.hoseId.clear();
        cleared.rangeFirst = cleared.rangeLast = cleared.routePoint = -1;
        m_selection = cleared;
    }
    emitChanged(ChangeEvent::Kind::HoseRemoved, hoseId);
    emitChanged(ChangeEvent::Kind::SelectionChanged);
    return removed;
}

void Document::syncProjectPoses()
{
    std::vector<formats::NodePose> poses;
    for (const formats::SceneReference& reference : m_project.scenes) {
        const formats::ImportedScene* imported = scene(reference.id);
        if (!imported) { // a missing scene keeps the poses written for it
            for (const formats::NodePose& pose : m_project.poses)
                if (pose.scene == reference.id) poses.push_back(pose);
            continue;
        }
        for (const auto& [key, transform] : m_pose)
            if (key.first == reference.id && transform && key.second >= 0 &&
                key.second < static_cast<int>(imported->nodes.size()))
                poses.push_back(
                    {key.first, imported->nodes[static_cast<size_t>(key.second)].path, *transform});
    }
    m_project.poses = std::move(poses);
}

UpdateResult Document::moveAttachmentsFully(Hose& hose, const std::vector<int>& ids,
                                            const std::vector<Frame>& frames)
{
    return formats::moveAttachmentsFully(hose, ids, frames);
}

void Document::closeMerge()
{
    ++m_mergeGeneration;
    std::vector<std::string> followed;
    followed.swap(m_gravityFollowed);
    for (const std::string& hoseId : followed) {
        if (!hoseDefinition(hoseId)) continue;
        rebuildHose(hoseId);
        settleHoseNow(hoseId);
        emitChanged(ChangeEvent::Kind::HoseShapeChanged, hoseId);
    }
}

void Document::settleHoseNow(const std::string& hoseId)
{
    const auto it = m_live.find(hoseId);
    if (it == m_live.end() || !it->second.hose || !it->second.hose->spec().gravity.enabled) return;
    LiveHose& live = it->second;
    while (!live.gravitySettled && live.gravitySteps < kGravityStepBudget) {
        ++live.gravitySteps;
        if (live.hose->step().movedPoints == 0) live.gravitySettled = true;
    }
    emit gravityStateChanged();
}

void Document::poseChanged(const NodeKey& node, bool following)
{
    ++m_poseSerial;
    syncProjectPoses();
    // Only what the moved part carries is moved: the part itself and the nodes under it. An
    // imported assembly is one scene, and its other parts, their colliders and the hoses
    // fixed to them stay as they are.
    const formats::ImportedScene* movedScene = scene(node.first);
    const auto carried = [&](int n) {
        for (; movedScene && n >= 0; n = movedScene->nodes[static_cast<size_t>(n)].parent)
            if (n == node.second) return true;
        return false;
    };
    // Colliders follow the pose: each one the part carries is placed again by the rigid part
    // of its posed world transform (setFrame; a scale set by a pose is applied the next time
    // the colliders are rebuilt, e.g. when a flag changes).
    std::vector<const MeshCollider*> movedColliders;
    for (const LiveCollider& c : m_colliders)
        if (c.sceneId == node.first && carried(c.node) &&
            c.collider->setFrame(nodeWorldFrame(c.sceneId, c.node)))
            movedColliders.push_back(c.collider.get());
    std::vector<std::string> rebuilt; // from their routes at the poses, colliders taken on
    for (const formats::HoseDefinition& definition : m_project.hoses) {
        const bool attachedHere =
            std::any_of(definition.attachments.begin(), definition.attachments.end(),
                        [&](const formats::HoseAttachment& attachment) {
                            return attachment.scene == node.first &&
                                   carried(movedScene->findNode(attachment.node));
                        }) ||
            std::any_of(definition.clips.begin(), definition.clips.end(),
                        [&](const formats::HoseClip& clip) {
                            return clip.scene == node.first &&
                                   carried(movedScene->findNode(clip.node));
                        });
        if (!attachedHere) continue;
        auto live = m_live.find(definition.id);
        if (live == m_live.end() || !live->second.hose) continue;
        // A hose is built again from its route at the file pose and moved straight to the
        // posed frames (formats::buildHose, as the export and the CLI build it): its shape
        // depends on where the parts are, not on the way they took, so a part moved out and
        // back leaves it as it was, and bends a far pose forced to give way come back. A hose
        // with gravity is settled there at once; during a drag it follows the move from its
        // current sag instead (a rebuild would lift it to its route at every drag step) and
        // closeMerge() builds and settles it where the drag ended.
        if (!definition.gravity.enabled || !following || !hoseAffectedByPose(definition)) {
            rebuildHose(definition.id);
            settleHoseNow(definition.id);
            rebuilt.push_back(definition.id);
            m_gravityFollowed.erase(
                std::remove(m_gravityFollowed.begin(), m_gravityFollowed.end(), definition.id),
                m_gravityFollowed.end());
        } else {
            if (std::find(m_gravityFollowed.begin(), m_gravityFollowed.end(), definition.id) ==
                m_gravityFollowed.end())
                m_gravityFollowed.push_back(definition.id);
            Hose& hoseObject = *live->second.hose;
            std::vector<int> ids;
            for (const Hose::Attachment& attachment : hoseObject.attachments())
                ids.push_back(attachment.id);
            const std::vector<Frame> frames = posedAttachmentFrames(definition);
            if (ids.size() == frames.size())
                live->second.lastUpdate = moveAttachmentsFully(hoseObject, ids, frames);
            wakeGravity(definition.id);
        }
        emitChanged(ChangeEvent::Kind::HoseShapeChanged, definition.id);
    }
    // A moved collider pushes the hoses it now overlaps out. A hose is built again (as one
    // fixed to the part is, rebuildHose: from its route, pushed by each posed collider's move
    // from the file pose), so its shape depends on where the parts are, not on the way they
    // took; one with gravity following a drag is pushed from its current sag instead (as the
    // runtime does).
    std::vector<std::string> pushed;
    for (auto& [hoseId, live] : m_live) {
        if (!live.hose || movedColliders.empty()) continue;
        const bool near = std::any_of(
            live.hose->colliders().begin(), live.hose->colliders().end(), [&](const auto& used) {
                return std::find(movedColliders.begin(), movedColliders.end(), used.get()) !=
                       movedColliders.end();
            });
        if (!near || std::find(rebuilt.begin(), rebuilt.end(), hoseId) != rebuilt.end()) continue;
        const formats::HoseDefinition* definition = hoseDefinition(hoseId);
        if (definition && (!definition->gravity.enabled || !following)) {
            pushed.push_back(hoseId);
            continue;
        }
        const std::uint64_t revision = live.hose->revision();
        live.lastUpdate = live.hose->resolveCollisions();
        if (live.hose->revision() != revision) {
            wakeGravity(hoseId);
            emitChanged(ChangeEvent::Kind::HoseShapeChanged, hoseId);
        }
    }
    for (const std::string& hoseId : pushed) {
        rebuildHose(hoseId, true);
        settleHoseNow(hoseId);
        emitChanged(ChangeEvent::Kind::HoseShapeChanged, hoseId);
    }
    ChangeEvent event;
    event.kind = ChangeEvent::Kind::PoseChanged;
    event.sceneId = node.first;
    event.node = node.second;
    emit changed(event);
}

void Document::insertScene(int index, formats::SceneReference reference,
                           formats::ImportedScene importedScene)
{
    clearMotionPreview();
    index = std::clamp(index, 0, static_cast<int>(m_project.scenes.size()));
    m_scenes[reference.id] = std::move(importedScene);
    m_project.scenes.insert(m_project.scenes.begin() + index, std::move(reference));
    rebuildColliders();
    ++m_poseSerial;
    emitChanged(ChangeEvent::Kind::ScenesChanged);
}

std::pair<formats::SceneReference, formats::ImportedScene>
Document::removeScene(const std::string& id)
{
    clearMotionPreview();
    auto it = std::find_if(m_project.scenes.begin(), m_project.scenes.end(),
                           [&](const formats::SceneReference& s) { return s.id == id; });
    std::pair<formats::SceneReference, formats::ImportedScene> removed;
    removed.first = *it;
    m_project.scenes.erase(it);
    removed.second = std::move(m_scenes.at(id));
    m_scenes.erase(id);
    for (auto pose = m_pose.begin(); pose != m_pose.end();)
        pose = pose->first.first == id ? m_pose.erase(pose) : std::next(pose);
    syncProjectPoses();
    if (m_selection.sceneId == id) {
        m_selection.sceneId.clear();
        m_selection.node = -1;
    }
    rebuildColliders();
    ++m_poseSerial;
    emitChanged(ChangeEvent::Kind::ScenesChanged);
    return removed;
}

std::optional<formats::ImportedScene>
Document::relinkScene(const std::string& id, std::string path,
                      std::optional<formats::ImportedScene> imported, std::string missingReason)
{
    clearMotionPreview();
    auto reference = std::find_if(m_project.scenes.begin(), m_project.scenes.end(),
                                  [&](const formats::SceneReference& s) { return s.id == id; });
    if (reference == m_project.scenes.end())
        throw InvalidArgument("no scene '" + id + "' to locate");
    reference->path = std::move(path);
    std::optional<formats::ImportedScene> before;
    if (auto it = m_scenes.find(id); it != m_scenes.end()) {
        before = std::move(it->second);
        m_scenes.erase(it);
    }
    for (auto pose = m_pose.begin(); pose != m_pose.end();)
        pose = pose->first.first == id ? m_pose.erase(pose) : std::next(pose);
    if (imported) {
        m_missingScenes.erase(id);
        m_scenes[id] = std::move(*imported);
        const formats::ImportedScene& now = m_scenes.at(id);
        for (const formats::NodePose& pose : m_project.poses)
            if (pose.scene == id)
                if (const int node = now.findNode(pose.node); node >= 0)
                    m_pose[{id, node}] = pose.localTransform;
    } else {
        m_missingScenes[id] = std::move(missingReason);
        if (m_selection.sceneId == id) {
            m_selection.sceneId.clear();
            m_selection.node = -1;
        }
    }
    ++m_poseSerial;
    m_meshBounds.clear();
    rebuildAllHoses();
    emitChanged(ChangeEvent::Kind::ScenesChanged);
    return before;
}

void Document::presetsChanged()
{
    // Hoses using a preset by name get the new values.
    for (const formats::HoseDefinition& definition : m_project.hoses)
        if (std::holds_alternative<formats::PresetName>(definition.material))
            rebuildHose(definition.id);
    emitChanged(ChangeEvent::Kind::PresetsChanged);
}

void Document::projectSettingsChanged()
{
    emitChanged(ChangeEvent::Kind::ProjectSettingsChanged);
}

void Document::rebuildHose(const std::string& hoseId, bool collidersFromFilePose)
{
    const formats::HoseDefinition* definition = hoseDefinition(hoseId);
    if (!definition) {
        m_live.erase(hoseId);
        return;
    }
    LiveHose& live = m_live[hoseId];
    live.buildSerial = ++m_buildCounter;
    live.metrics.reset();
    live.dragPoint = -1;
    const auto missing = [&]() -> std::string {
        for (const formats::HoseAttachment& attachment : definition->attachments)
            if (m_missingScenes.count(attachment.scene)) return attachment.scene;
        for (const formats::HoseClip& clip : definition->clips)
            if (m_missingScenes.count(clip.scene)) return clip.scene;
        return {};
    }();
    if (!missing.empty()) {
        live.hose.reset();
        live.error = "it is fixed to scene '" + missing + "', which is missing (" +
                     m_missingScenes.at(missing) + "); locate the scene to build it";
        return;
    }
    try {
        // m_project.poses mirrors the overrides: buildHose builds at the file pose and moves
        // the attachments to the posed frames, exactly as the export and the CLI do.
        live.hose = formats::buildHose(m_project, *definition, m_scenes, &live.lastUpdate);
        live.error.clear();
        // collidersFromFilePose (a hose a moved collider reaches, not fixed to the moved part):
        // the hose takes its colliders on as they are at the file pose (each at its frame
        // there) and the pushing out below sweeps each posed collider's move from there to its
        // frame now, relative to the hose, in one step: a collider posed across the hose pushes
        // it from the side the file pose has it on, and the shape depends on the poses only,
        // not on the way a part took to them.
        std::vector<std::pair<MeshCollider*, Frame>> posed;
        for (const LiveCollider& c : m_colliders) {
            if (!collidersFromFilePose) break;
            const Frame now = c.collider->frame();
            const Frame atFilePose = filePoseWorldFrame(c.sceneId, c.node);
            if ((atFilePose.translation != now.translation ||
                 atFilePose.rotation.coeffs() != now.rotation.coeffs()) &&
                c.collider->setFrame(atFilePose))
                posed.push_back({c.collider.get(), now});
        }
        applyColliders(hoseId);
        for (const auto& [collider, now] : posed) // back where the poses put them
            static_cast<void>(collider->setFrame(now));
        // Built where its route and the parts put it, then out of the colliders it overlaps
        // there (a flagged part it was laid through, a collider moved onto it). Where its
        // length cannot go round them (Infeasible), it keeps the built shape, every length in
        // its band, and the result says how deep it runs in (the Problems panel lists it).
        if (!live.hose->colliders().empty()) {
            Hose built = *live.hose;
            const UpdateResult pushed = live.hose->resolveCollisions();
            if (pushed.status == Status::Infeasible) *live.hose = std::move(built);
            live.lastUpdate = pushed;
        }
        if (!m_motionLocal.empty()) followMotionPreview(hoseId);
        wakeGravity(hoseId);
    } catch (const std::exception& error) {
        live.hose.reset();
        live.error = error.what();
    }
}

void Document::rebuildAllHoses()
{
    m_live.clear();
    rebuildColliders(); // first: each hose is pushed out of them as it is built
    for (const formats::HoseDefinition& definition : m_project.hoses)
        rebuildHose(definition.id);
}

bool Document::hoseAffectedByPose(const formats::HoseDefinition& definition) const
{
    const auto posed = [&](const std::string& sceneId, const std::string& path) {
        const formats::ImportedScene* imported = scene(sceneId);
        if (!imported) return false;
        for (int n = imported->findNode(path); n >= 0;
             n = imported->nodes[static_cast<size_t>(n)].parent) {
            const auto it = m_pose.find({sceneId, n});
            if (it != m_pose.end() && it->second) return true;
            if (m_motionLocal.count({sceneId, n}) > 0) return true;
        }
        return false;
    };
    return std::any_of(definition.attachments.begin(), definition.attachments.end(),
                       [&](const formats::HoseAttachment& a) { return posed(a.scene, a.node); }) ||
           std::any_of(definition.clips.begin(), definition.clips.end(),
                       [&](const formats::HoseClip& c) { return posed(c.scene, c.node); });
}

std::vector<Frame> Document::posedAttachmentFrames(const formats::HoseDefinition& definition) const
{
    std::vector<Frame> frames;
    for (const formats::HoseAttachment& attachment : definition.attachments) {
        const formats::ImportedScene* imported = scene(attachment.scene);
        const int node = imported ? imported->findNode(attachment.node) : -1;
        Frame offset = attachment.offset; // as formats::buildHose does
        offset.rotation.normalize();
        frames.push_back(nodeWorldFrame(attachment.scene, node) * offset);
    }
    for (const formats::HoseClip& clip : definition.clips) { // after them, as buildHose adds them
        const formats::ImportedScene* imported = scene(clip.scene);
        const int node = imported ? imported->findNode(clip.node) : -1;
        Frame offset = clip.offset;
        offset.rotation.normalize();
        frames.push_back(nodeWorldFrame(clip.scene, node) * offset);
    }
    return frames;
}

void Document::emitChanged(ChangeEvent::Kind kind, const std::string& hoseId)
{
    ChangeEvent event;
    event.kind = kind;
    event.hoseId = hoseId;
    emit changed(event);
}

} // namespace chaintube::editor
