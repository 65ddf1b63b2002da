// ChainTube editor — the document: project model, imported scenes, live hoses, undo stack.
//
// Tiled-like: the Document owns everything an author edits and a QUndoStack; every edit is a
// QUndoCommand (commands.h) that changes the document through the mutators at the end of this
// class and reports what changed with one typed signal, changed(ChangeEvent). Views only
// listen. The Document knows nothing about widgets or OpenGL (it links QtCore/QtGui only) and
// can be used under QT_QPA_PLATFORM=offscreen.
//
// State and what is saved:
//  * project()        — the formats::Project; this is what Save writes.
//  * scenes()         — the imported scenes at the pose their files give ("file pose").
//  * pose overrides   — node transforms the author moved (a part moved or rotated; the
//                       hoses follow live). Undoable, and mirrored into project().poses
//                       (formats::NodePose, per node path), so Save writes them and Open
//                       restores them; export builds the hoses at them like the CLI.
//  * live hoses       — one chaintube::Hose per project hose, built from its definition with
//                       formats::buildHose at the file pose, then its attachments moved to the
//                       posed node frames. A grab-drag changes only the live hose until it is
//                       committed (commitHoseDrag), which writes the dragged axis as the route
//                       and keeps the hose's length (HoseDefinition::length): only an explicit
//                       length edit (makeSetHoseLength) changes how long a hose is.
//  * live gravity     — a hose with gravity on (HoseDefinition::gravity) sags in its live
//                       shape: stepGravity() advances it (Hose::step) until it settles. This is
//                       derived state, never an undo step and never the modified flag: the file
//                       keeps the authored route and the gravity flag, and a reload reproduces
//                       the sag by the same deterministic steps.
//  * live colliders   — a MeshCollider per part flagged in project().colliders, built from
//                       the part's own meshes at its posed world transform
//                       (formats::nodeCollider). Every live hose stays outside them during
//                       drags, part moves and gravity, except the parts its attachments are on
//                       and their ancestors (formats/collider_exemption.h, as the runtime and
//                       the clearance check). Rebuilt when a flag changes, moved with the pose;
//                       a hose is pushed out of them when it is built and when a flag it is
//                       concerned by changes (then it is built again).
#pragma once

#include "chaintube/formats/motion.h"
#include "chaintube/formats/project.h"
#include "chaintube/formats/project_hoses.h"
#include "chaintube/hose.h"
#include "chaintube/metrics.h"

#include <QObject>
#include <QUndoStack>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace chaintube::editor {

/// What changed. Views re-read what they show for the kinds they care about.
struct ChangeEvent
{
    enum class Kind {
        ProjectReplaced,        ///< new/open/recover: everything changed
        ScenesChanged,          ///< a scene was imported or removed
        HoseAdded,              ///< hoseId was added
        HoseRemoved,            ///< hoseId was removed
        HoseChanged,            ///< hoseId's definition changed (and its live hose was rebuilt)
        HoseShapeChanged,       ///< hoseId's live axis moved (drag, a part it is fixed to moved)
        PoseChanged,            ///< a scene node's transform override changed (sceneId, node)
        CollidersChanged,       ///< the project's collider flags changed (sceneId, node)
        PresetsChanged,         ///< the project's material presets changed
        SocketsChanged,         ///< project().sockets changed (added, removed, edited)
        ProjectSettingsChanged, ///< name or export settings changed
        SelectionChanged,       ///< selection() changed (not an undoable edit)
        FileStateChanged,       ///< file name or modified flag changed
    };
    Kind kind = Kind::ProjectReplaced;
    std::string hoseId;
    std::string sceneId;
    int node = -1;
};

/// What is selected. A hose and a scene node can be selected at the same time, so that a hose
/// segment can be fixed to the node.
struct Selection
{
    std::string hoseId;  ///< "" = none
    int rangeFirst = -1; ///< selected axis points [rangeFirst, rangeLast] of hoseId; −1 none
    int rangeLast = -1;
    int routePoint = -1; ///< selected route point of hoseId, −1 none
    std::string sceneId; ///< selected scene node: scene id and node index, −1 none
    int node = -1;
    std::string socketId; ///< selected socket (formats::Socket::id), "" = none
    bool operator==(const Selection& o) const
    {
        return hoseId == o.hoseId && rangeFirst == o.rangeFirst && rangeLast == o.rangeLast &&
               routePoint == o.routePoint && sceneId == o.sceneId && node == o.node &&
               socketId == o.socketId;
    }
    bool operator!=(const Selection& o) const { return !(*this == o); }
};

/// A scene node: scene id and node index.
using NodeKey = std::pair<std::string, int>;

/// Where a hose comes closer to a scene object than the clearance threshold: set by
/// the problems panel, drawn by the renderer (a line from the hose surface to the object).
struct ClearanceMarker
{
    std::string hoseId;
    int axisPoint = -1;
    Vec3 onHose = Vec3::Zero();   ///< world metres
    Vec3 onObject = Vec3::Zero(); ///< world metres
};

/// A project read from disk with its scenes imported: made on a worker thread, adopted by a
/// Document on the GUI thread.
struct LoadedProject
{
    formats::Project project;
    std::filesystem::path file; ///< empty for an untitled project
    formats::ImportedScenes scenes;
    /// Scenes of the project whose file cannot be found (no such file, an unknown named
    /// root): scene id → why, e.g. "scenes/rig.gltf: no such file (/work/p/scenes/rig.gltf)".
    /// They are not in `scenes`; the project opens anyway (Document::missingScenes).
    std::map<std::string, std::string> missingScenes;
};

/// Reads a project file and imports its scenes (thread-safe; touches no Document).
/// progress(fraction) returning false cancels (throws formats::Cancelled). A scene whose file
/// cannot be found (it does not exist, or its named root is unknown) is not imported but
/// listed in LoadedProject::missingScenes, so that the project still opens; its poses are kept
/// as written, hoses fixed to it cannot be built until it is located
/// (RelinkSceneCommand). Throws what loadProject throws, and what importProjectScenes throws
/// for a scene file that is there but cannot be read. `textOverride`, when given, is parsed instead
/// of the file's contents (crash recovery: an autosave parsed as if it were `file`).
LoadedProject readProject(const std::filesystem::path& file, const formats::NamedRoots& roots,
                          const std::function<bool(double)>& progress = {},
                          const std::optional<std::string>& textOverride = std::nullopt);

class Document : public QObject
{
    Q_OBJECT
public:
    /// An untitled project with the standard material presets.
    explicit Document(formats::NamedRoots roots, QObject* parent = nullptr);
    ~Document() override;

    // --- file -------------------------------------------------------------------------------
    /// Replaces everything with `loaded`; clears the undo stack (clean) and the selection.
    void adopt(LoadedProject loaded);
    /// Replaces everything with an untitled project with standard presets.
    void reset(const std::string& projectName = "Untitled");
    /// Saves with formats::saveProject (atomic, validated) and marks the stack clean.
    /// Hoses with gravity on are first settled (settleGravity()): the file holds the authored
    /// route and the gravity flag, a reload settles the hose again by the same deterministic
    /// steps, so what is on screen after saving is what the file reproduces.
    /// Saved into another folder than the project's (Save As), the project's paths (scenes,
    /// export target) are first re-expressed from there (formats::rebaseProject: relative when
    /// the file lies inside the new folder, else absolute), and the document keeps them so.
    /// Throws what saveProject and rebaseProject throw; then nothing changed.
    void save(const std::filesystem::path& file);
    const std::filesystem::path& fileName() const { return m_file; }
    /// True if there are edits since the last adopt/reset/save.
    bool isModified() const { return !m_undoStack.isClean() || m_forcedModified; }
    /// Marks the document modified although the stack is clean (after recovering an autosave).
    void setForcedModified(bool modified);
    const formats::NamedRoots& roots() const { return m_roots; }
    void setRoots(formats::NamedRoots roots) { m_roots = std::move(roots); }

    QUndoStack* undoStack() { return &m_undoStack; }

    // --- model ------------------------------------------------------------------------------
    const formats::Project& project() const { return m_project; }
    const formats::ImportedScenes& scenes() const { return m_scenes; }
    const formats::ImportedScene* scene(const std::string& sceneId) const;
    /// Scenes of project() whose file was not found when the project was read: scene id → why
    /// (see LoadedProject::missingScenes). Not in scenes(); RelinkSceneCommand locates one.
    const std::map<std::string, std::string>& missingScenes() const { return m_missingScenes; }

    int hoseCount() const { return static_cast<int>(m_project.hoses.size()); }
    /// Index of the hose definition with this id, or −1.
    int hoseIndex(const std::string& hoseId) const;
    const formats::HoseDefinition* hoseDefinition(const std::string& hoseId) const;
    /// The live hose, or nullptr if its definition could not be built (see hoseBuildError).
    const Hose* hose(const std::string& hoseId) const;
    /// Why a hose could not be built ("" if it was).
    std::string hoseBuildError(const std::string& hoseId) const;
    /// Incremented each time the live hose object is rebuilt (renderers drop cached topology).
    std::uint64_t hoseBuildSerial(const std::string& hoseId) const;
    /// measure() of the live hose (cached; recomputed when its revision changes).
    const HoseMetrics* hoseMetrics(const std::string& hoseId) const;
    /// What the last update the document made to the live hose returned: its attachments moved
    /// with a part (poseChanged, or a rebuild at a posed part), a moved collider pushing it, a
    /// flag change pushing it out. A default (Ok) result for an unknown hose or before any.
    UpdateResult lastUpdate(const std::string& hoseId) const;

    /// Checks that `definition` would build (material, profile, diameter, route) without
    /// changing anything. Returns "" if valid, else the reason, for the properties panel to
    /// refuse a value with a message.
    std::string validateHoseDefinition(const formats::HoseDefinition& definition) const;

    /// A hose id not used yet ("hose-1", "hose-2", …).
    std::string unusedHoseId() const;
    /// A socket id not used yet ("socket-1", "socket-2", …).
    std::string unusedSocketId() const;
    /// Checks a socket's values as the project reader would (capture radius > 0 m, capture
    /// angle in (0, π] rad, a non-zero axis, a non-empty tag, finite numbers). Returns "" if
    /// valid, else the reason, for the properties panel to refuse a value with a message.
    static std::string validateSocket(const formats::Socket& socket);
    /// The socket where its part is now: world position and unit axis (the node's rigid frame
    /// with the pose overrides). False when its scene or node is missing.
    bool socketWorld(const formats::Socket& socket, Vec3* position, Vec3* axis) const;

    // --- pose -------------------------------------------------------------------------------
    /// The node's parent ← node transform: the override if any, else the file's.
    formats::Mat4 nodeLocalTransform(const std::string& sceneId, int node) const;
    /// world ← node with overrides applied along the parent chain.
    formats::Mat4 nodeWorldTransform(const std::string& sceneId, int node) const;
    /// Rigid part of nodeWorldTransform (the frame attachments use).
    Frame nodeWorldFrame(const std::string& sceneId, int node) const;
    /// Centre of the world bounding box of the node's meshes and its descendants' at the
    /// current pose (world metres): where the part gizmo sits and what it turns about. The
    /// node's origin when it has no mesh under it. A CAD node's origin can lie far outside
    /// the part (an assembly's origin, a part modelled away from zero).
    Vec3 partCentre(const std::string& sceneId, int node) const;
    /// The hose's route as the viewport draws it (world metres): the route itself while no
    /// part the hose is fixed to is moved; otherwise each route point carried by the motion
    /// of the hose's attachments (file pose → pose): rigidly with the one attachment, or, between
    /// two, by a blend of their motions after where the point lies along the route. So the
    /// route line follows the parts. Empty for an unknown hose.
    std::vector<Vec3> displayRoute(const std::string& hoseId) const;
    /// True if a part the hose is fixed to (or one of its ancestors) is moved from its file
    /// pose: the route (stored at the file pose) is then not edited by dragging.
    bool hoseFollowsMovedPart(const std::string& hoseId) const;
    /// Overrides set by the author (nullopt entries mean "back to the file pose").
    const std::map<NodeKey, std::optional<formats::Mat4>>& poseOverrides() const { return m_pose; }
    /// Increments whenever any override changes (pickers rebuild instance transforms).
    std::uint64_t poseSerial() const { return m_poseSerial; }

    // --- motion preview (not an edit) -------------------------------------------------------
    /// Poses the moving parts of project().motions at `values` (one per motion: radians for a
    /// hinge, metres for a slider; formats::PartMotions on top of the project's pose) and moves
    /// the hoses fixed to them as a part drag does (moveAttachmentsFully), in steps no larger
    /// than 1/kMotionPreviewSteps of a motion's range; colliders the parts carry move along.
    /// A preview, like scrubbing a CAD assembly's motion: no undo step, no modified flag,
    /// project() unchanged; nodeLocalTransform() and everything drawn follow it. Values all 0
    /// is the project's pose: the hoses it moved are built again exactly as the project gives
    /// them. Any edit (a command pushed, undone or redone), a new project or a scene change
    /// ends the preview (clearMotionPreview). Values are clamped to each motion's range.
    /// Returns false and changes nothing for a wrong count, a non-finite value or a motion the
    /// scenes cannot resolve (`why` says which).
    bool setMotionPreview(const std::vector<double>& values, std::string* why = nullptr);
    /// Back to the project's pose (setMotionPreview with every value 0); emits
    /// motionPreviewChanged(). Nothing happens when no preview is active.
    void clearMotionPreview();
    /// The previewed values, one per motion; empty while the parts are at the project's pose.
    const std::vector<double>& motionPreview() const { return m_motionValues; }
    static constexpr int kMotionPreviewSteps = 40;

    // --- selection (not undoable) -----------------------------------------------------------
    const Selection& selection() const { return m_selection; }
    void setSelection(const Selection& selection);

    // --- live drag --------------------------------------------------------------------------
    /// Moves axis point `point` of the live hose towards `target` (world metres) with one
    /// Hose::grab under UpdateBudget::realtime(), as a runtime frame does: the work of a mouse
    /// move is bounded, and what it cannot finish is pending (UpdateResult::pending) and goes on
    /// with the next move (or the hose's gravity step). Emits HoseShapeChanged. Not an undo step
    /// until commitHoseDrag(). A fixed point, an unknown hose or an index out of range gives
    /// Status::InvalidInput.
    UpdateResult dragHosePoint(const std::string& hoseId, int point, const Vec3& target);
    /// Finishes a live drag without a budget (the mouse released): the pending work
    /// (Hose::finishPending), then the last drag target again, up to kDragGrabs grabs, until
    /// the point is there or gets no nearer; where one grab gets no nearer, the way is cut into
    /// steps of kDragSubStep (at most kDragSubSteps) first. The hose is then unbounded again and
    /// nothing is pending. The result is the last grab's, with the points moved and the
    /// iterations of all of them (movedPoints 0 when there was no drag). commitHoseDrag() calls it.
    UpdateResult finishHoseDrag(const std::string& hoseId);
    static constexpr int kDragGrabs = 16;
    static constexpr double kDragSubStep = 0.5e-3; ///< metres
    static constexpr int kDragSubSteps = 64;
    /// Ends a drag: finishes it (finishHoseDrag), then pushes a command that writes the live
    /// axis as the hose's route, its length
    /// unchanged (a hose without one gets the rest length it had). The hose is rebuilt from
    /// the route exactly as it was dragged (formats::buildHose takes a valid axis as it is),
    /// so save → load gives the same shape. `draggedPoint` names the step in the history
    /// ("Drag point 7 of <hose>"). Returns false (and restores the shape before the drag) when
    /// the hose is fixed to a node that is moved from its file pose, because the route is
    /// stored at the file pose; `why` then says so.
    bool commitHoseDrag(const std::string& hoseId, int draggedPoint = -1,
                        std::string* why = nullptr);
    /// Abandons a drag: the live hose is rebuilt from its definition.
    void cancelHoseDrag(const std::string& hoseId);

    // --- live gravity -----------------------------------------------------------------------
    /// At most this many steps per hose after it last changed; a hose still moving then is
    /// left where it is (reported by gravityUnsettledHoses()) so that the editor goes idle.
    /// The export settles with the same budget, so it writes the shape the editor shows.
    static constexpr int kGravityStepBudget = formats::kSettleStepBudget;
    /// One Hose::step() of every live hose with gravity on that has not settled yet (the main
    /// window calls it on a timer while gravityActive()). A simulation of the live shape, not
    /// an edit: no undo step, no modified flag; the definition's route stays as authored.
    /// Emits HoseShapeChanged for each hose that moved (after stepping all of them); returns
    /// how many moved. A hose counts as settled when its step moved nothing.
    int stepGravity();
    /// Live gravity by the clock: `seconds` of wall time (clamped to Gravity::kMaxFrameSeconds,
    /// a long pause adds no more than 0.1 s) are added to what is owed and every whole
    /// Gravity::kFrameSeconds owed is one stepGravity(); the rest is kept for the next call. So
    /// the hoses fall at the speed of time whatever the timer's rate or jitter, and by the same
    /// steps as settleGravity() and the export (the same shapes, bit for bit). Nothing is owed
    /// while no hose settles. A non-finite or negative time adds nothing. Returns the
    /// stepGravity() calls made.
    int advanceGravity(double seconds);
    /// True while some hose with gravity on is not settled and has step budget left.
    bool gravityActive() const;
    /// Steps until every gravity hose is settled or out of budget (what the timer would do,
    /// at once). Returns the number of stepGravity() calls made.
    int settleGravity();
    /// Hoses with gravity on that used their whole step budget without settling.
    std::vector<std::string> gravityUnsettledHoses() const;
    enum class GravityState { Off, Settling, Settled, OutOfBudget };
    GravityState gravityState(const std::string& hoseId) const;
    /// Steps made since the hose last changed.
    int gravitySteps(const std::string& hoseId) const;

    // --- colliders --------------------------------------------------------------------------
    /// True if the node is flagged as a collider in project().colliders.
    bool isCollider(const std::string& sceneId, int node) const;
    /// The colliders the live hose uses (empty for an unknown or unbuilt hose).
    std::vector<std::shared_ptr<const MeshCollider>> hoseColliders(const std::string& hoseId) const;

    // --- merging ----------------------------------------------------------------------------
    /// Ends the current merge run: the next value change becomes a new undo step even if it
    /// changes the same thing (call when a slider or a drag is released).
    /// A hose with gravity that followed a part drag step by step (poseChanged with
    /// `following`) is built again for the pose the run ended at and settled there now, so its
    /// shape does not depend on the way the part took.
    void closeMerge();
    std::uint64_t mergeGeneration() const { return m_mergeGeneration; }

    // --- a canonical description for tests --------------------------------------------------
    /// serialiseProject(project()) plus the pose overrides and the scene ids: two documents
    /// with the same state give the same text.
    std::string stateFingerprint() const;

    // --- mutators used by commands (commands.h); they emit changed() ------------------------
    formats::Project& mutableProject() { return m_project; }
    formats::HoseDefinition* mutableHoseDefinition(const std::string& hoseId);
    std::optional<formats::Mat4>* mutablePoseOverride(const NodeKey& node);
    /// Rebuilds the live hose from its definition and the current pose; emits HoseChanged.
    void hoseDefinitionChanged(const std::string& hoseId);
    /// Inserts a definition at `index` and builds it; emits HoseAdded.
    void insertHose(int index, formats::HoseDefinition definition);
    /// Removes the hose; returns its definition. Emits HoseRemoved.
    formats::HoseDefinition removeHose(const std::string& hoseId);
    /// Builds every hose fixed under the changed node again at the poses (formats::buildHose:
    /// from its route at the file pose straight to the posed frames, so its shape is a function
    /// of the poses, not of the way the parts took). A hose with gravity is built again and
    /// settled at once (settleHoseNow) — except while `following` a drag (the first application
    /// of a part-move command, not an undo or a redo): then it is moved from its current sag to
    /// the posed frames (moveAttachmentsFully), live gravity goes on, and closeMerge() builds
    /// and settles it for the pose the drag ended at. A hose near a collider the part carries
    /// is built again too (rebuildHose: pushed by the collider's move from the file pose); one
    /// with gravity following a drag is pushed from its current sag (resolveCollisions). Emits
    /// PoseChanged and HoseShapeChanged.
    void poseChanged(const NodeKey& node, bool following = false);
    /// formats::moveAttachmentsFully: a part move as the editor makes it (not bound to a frame).
    static UpdateResult moveAttachmentsFully(Hose& hose, const std::vector<int>& ids,
                                             const std::vector<Frame>& frames);
    /// Adds/removes an imported scene with its reference (import command).
    void insertScene(int index, formats::SceneReference reference, formats::ImportedScene scene);
    std::pair<formats::SceneReference, formats::ImportedScene> removeScene(const std::string& id);
    /// Points scene `id` at `path` (as written in the project). With `imported`, the scene is
    /// there: it is no longer missing, its poses of project().poses apply again; without, it
    /// becomes missing for `missingReason` (its poses are kept in project().poses). Rebuilds
    /// the colliders and every hose; emits ScenesChanged. Returns the imported scene it held
    /// before (none when it was missing).
    std::optional<formats::ImportedScene>
    relinkScene(const std::string& id, std::string path,
                std::optional<formats::ImportedScene> imported, std::string missingReason);
    void presetsChanged();
    void projectSettingsChanged();
    /// project().sockets changed; emits SocketsChanged (and SelectionChanged when the selected
    /// socket went away).
    void socketsChanged();
    /// project().colliders changed (a node's flag); emits CollidersChanged for it.
    void collidersChanged(const NodeKey& node);

    /// Clearance violations to highlight (a view state, not an edit: no undo, no modified
    /// flag). Emits clearanceMarkersChanged() when they differ.
    void setClearanceMarkers(std::vector<ClearanceMarker> markers);
    const std::vector<ClearanceMarker>& clearanceMarkers() const { return m_clearanceMarkers; }

signals:
    void changed(const chaintube::editor::ChangeEvent& event);
    void clearanceMarkersChanged();
    /// A hose with gravity on started settling (it was built, dragged or a part it is fixed to
    /// moved: whoever drives stepGravity() should start), settled, or ran out of step budget.
    void gravityStateChanged();
    /// motionPreview() changed (a scrub, a reset, or an edit that ended the preview).
    void motionPreviewChanged();

private:
    std::vector<ClearanceMarker> m_clearanceMarkers;
    /// Motion preview (motion_preview.cpp): the values, the motions resolved against a copy
    /// of the scenes' nodes (no meshes), and the moving nodes' previewed local transforms,
    /// which nodeLocalTransform() gives before any override.
    std::vector<double> m_motionValues;
    std::unique_ptr<formats::PartMotions> m_partMotions;
    formats::ImportedScenes m_motionNodes;
    std::map<NodeKey, formats::Mat4> m_motionLocal;
    std::vector<std::string> m_motionMovedHoses; ///< hoses the preview moved (rebuilt on reset)
    /// Drops the preview state without touching the hoses (a rebuild follows).
    void dropMotionPreview();
    /// Poses the moving nodes at `values` (m_motionLocal) and moves what they carry.
    void applyMotionPose(const std::vector<double>& values);
    /// A hose just built at the project's pose: its attachments on previewed parts moved there.
    void followMotionPreview(const std::string& hoseId);
    struct LiveHose
    {
        std::optional<Hose> hose;
        std::string error;
        std::uint64_t buildSerial = 0;
        mutable std::optional<HoseMetrics> metrics;
        mutable std::uint64_t metricsRevision = 0;
        bool gravitySettled = true; ///< stepGravity(): the last step moved nothing
        int gravitySteps = 0;       ///< steps since the hose last changed (kGravityStepBudget)
        UpdateResult lastUpdate;    ///< see Document::lastUpdate()
        std::vector<NodeKey> colliderNodes; ///< the flagged parts it stays outside
        int dragPoint = -1;                 ///< the live drag's point (−1: none)
        Vec3 dragTarget = Vec3::Zero();     ///< its last target (world)
    };
    /// Marks a live hose with gravity on as settling (after a build, a drag, a part move);
    /// emits gravityStateChanged().
    void wakeGravity(const std::string& hoseId);
    /// Builds the hose from its definition at the poses (formats::buildHose), gives it its
    /// colliders and pushes it out of them. With collidersFromFilePose (a hose a moved collider
    /// reaches, fixed to no moved part) it takes the colliders on as they are at the file pose,
    /// so that the pushing out sweeps each posed collider's move from there relative to it.
    void rebuildHose(const std::string& hoseId, bool collidersFromFilePose = false);
    /// The rigid part of a node's world transform at the file pose (no pose override, no
    /// motion preview).
    Frame filePoseWorldFrame(const std::string& sceneId, int node) const;
    /// Steps a live hose with gravity on until it settles or its step budget runs out, as
    /// stepGravity() would over the next frames (the same steps, so the same shape).
    void settleHoseNow(const std::string& hoseId);
    /// Builds m_colliders from project().colliders at the current pose and gives every live
    /// hose its colliders (applyColliders).
    void rebuildColliders();
    /// Hose::setColliders with the flagged parts the hose is not exempt from.
    void applyColliders(const std::string& hoseId);
    /// Writes the non-empty overrides into m_project.poses (project scene order, then node
    /// order) after an override changed.
    void syncProjectPoses();
    void rebuildAllHoses();
    bool hoseAffectedByPose(const formats::HoseDefinition& definition) const;
    /// Frames of the definition's attachments under the current pose.
    std::vector<Frame> posedAttachmentFrames(const formats::HoseDefinition& definition) const;
    void emitChanged(ChangeEvent::Kind kind, const std::string& hoseId = {});

    formats::NamedRoots m_roots;
    formats::Project m_project;
    std::filesystem::path m_file;
    formats::ImportedScenes m_scenes;
    std::map<std::string, std::string> m_missingScenes;
    std::map<std::string, LiveHose> m_live;
    struct LiveCollider
    {
        std::string sceneId;
        int node = -1;
        std::shared_ptr<MeshCollider> collider;
    };
    std::vector<LiveCollider> m_colliders;
    /// Bounds of each scene mesh in its own frame (partCentre()), made when first needed.
    mutable std::map<const formats::SceneMesh*, std::pair<Vec3, Vec3>> m_meshBounds;
    std::map<NodeKey, std::optional<formats::Mat4>> m_pose;
    std::uint64_t m_poseSerial = 1;
    std::uint64_t m_buildCounter = 0;
    std::uint64_t m_mergeGeneration = 1;
    /// Hoses with gravity that followed a drag step by step since the last closeMerge().
    std::vector<std::string> m_gravityFollowed;
    /// advanceGravity(): wall time owed to live gravity, less than one step (seconds).
    double m_gravityOwed = 0.0;
    Selection m_selection;
    QUndoStack m_undoStack;
    bool m_forcedModified = false;
};

} // namespace chaintube::editor

Q_DECLARE_METATYPE(chaintube::editor::ChangeEvent)
