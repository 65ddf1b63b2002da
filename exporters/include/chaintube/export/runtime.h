// ChainTube runtime — loads an exported glTF/GLB with its hose-rig descriptor and runs the hoses.
//
// This is what a C++ VR platform links (target chaintube_runtime: the core library, no Qt, no
// tinygltf or JSON types in this header). Per frame the platform tells the runtime where scene
// objects moved (setNodeTransform) and where the user's hands are (grab), then reads back the
// joint transforms to pose the skinned meshes (jointPoses), or the surface vertices directly.
//
// Frames: node transforms are glTF parent-local T·R·S; world = product of local transforms
// from the scene root. Units: metres, radians. A joint's world transform is rigid: (ring
// centre, ring rotation with columns alignment, binormal, tangent).
#pragma once

#include "chaintube/collision.h"
#include "chaintube/export/rig_descriptor.h"
#include "chaintube/hose.h"
#include "chaintube/reel.h"
#include "chaintube/surface.h"
#include "chaintube/tension.h"

#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace chaintube::rig {

/// One glTF node as the runtime sees it.
struct RigNode
{
    std::string name;
    int parent = -1;
    NodeTransform local; ///< parent ← node (a glTF `matrix` is decomposed)
};

/// A collider node's triangles in the node's own frame (glTF mesh data: metres before the
/// node's world transform), all triangle primitives of its mesh concatenated.
struct ColliderMesh
{
    std::vector<float> positions;       ///< x, y, z per vertex
    std::vector<std::uint32_t> indices; ///< three per triangle
};

/// A joint's pose: in its glTF parent's frame (what to write into the node's TRS) and in world.
struct JointPose
{
    int node = -1;
    NodeTransform local;
    Frame world;
};

/// An attachment of a running hose: the descriptor's as exported (in its order), then each one
/// HoseRuntime::attachEnd() made.
struct LiveAttachment
{
    int node = -1;        ///< glTF node it is on; −1: fixed in the world
    Frame offset;         ///< attachment frame = rigid(world(node)) · offset
    int firstPoint = 0;   ///< the axis points it fixes, first … last
    int lastPoint = 0;    ///<
    bool attached = true; ///< false once detachEnd() let go of it (its index stays)
    int id = -1;          ///< its Hose attachment id while attached
    int socket = -1;      ///< the socket it plugs the end into (plug(), a snap-in); −1: none;
                          ///< kept once detached (socketOccupant() counts only attached ones)
    /// Seconds of update() time left until a plugged end sits in its socket (0: seated).
    double easingSeconds = 0.0;
};

/// What HoseRuntime::plug(), unplug() and release() did with a hose end and the sockets.
struct PlugResult
{
    /// Ok: done (for release(): let go, and plugged when socket ≥ 0); InvalidInput: refused,
    /// nothing changed.
    Status status = Status::InvalidInput;
    int socket = -1;     ///< the socket plugged into or unplugged from; −1: none
    int end = -1;        ///< the hose end: 0 (points 0 and 1) or 1 (the last two); −1: none
    int attachment = -1; ///< the hose's attachment (attachment()) that holds or held the end
    double easingSeconds = 0.0; ///< update() time until a plugged end sits in its socket (s)
    explicit operator bool() const { return status != Status::InvalidInput; }
};

/// Which hose end a socket holds (HoseRuntime::socketOccupant); hose −1 when it is free.
struct SocketOccupant
{
    int hose = -1;
    int end = -1;        ///< 0 or 1
    int attachment = -1; ///< the hose's attachment that holds the end
};

/// What HoseRuntime::cut() did.
struct CutResult
{
    /// Ok, or InvalidInput: refused, nothing changed.
    Status status = Status::InvalidInput;
    /// The hose index of the piece beyond the cut (the hose cut keeps its index and the piece
    /// before the cut).
    int newHose = -1;
};

/// What changed for one hose in a call.
struct HoseUpdate
{
    int hose = -1;
    UpdateResult result;
};

/// A file of an export (the glTF, a buffer, the sidecar descriptor) cannot be read: missing or
/// no permission. what() names the file.
class UnreadableFile : public Error
{
public:
    using Error::Error;
};

/// An export held in memory: a platform's asset bytes, or what a browser fetched.
struct ExportInMemory
{
    /// Names the export in messages and the report, as a file name would ("rig.glb").
    std::string name = "<memory>";
    /// The .glb bytes, or a .gltf's JSON text.
    std::string_view gltf;
    /// buffers[i]: the bytes of /buffers/i for a buffer with a uri (a .gltf's .bin). Entries for
    /// a GLB's BIN chunk (the buffer without a uri) are not used and may be empty.
    std::vector<std::string_view> buffers;
    /// The sidecar descriptor's text (<name>.hoses.json), used only when the glTF has no
    /// CHAINTUBE_hose_rig extension; empty when not given.
    std::string_view sidecarDescriptor;
};

/// Where the descriptor came from and what the loader noticed.
struct RuntimeLoadReport
{
    std::string descriptorSource; ///< "<file>#CHAINTUBE_hose_rig" or the sidecar path
    std::vector<std::string> warnings;
};

class HoseRuntime
{
public:
    /// Loads an exported .glb or .gltf (+ .bin): the node hierarchy, and the descriptor from the
    /// CHAINTUBE_hose_rig extension, or from the sidecar <name>.hoses.json when the glTF has no
    /// extension (e.g. after a tool that drops unknown extensions). Rebuilds every hose with
    /// its attachments as exported, its gravity and torsion (HoseSpec), and its colliders: a
    /// MeshCollider per descriptor collider node, built from the node's glTF mesh, which every
    /// hose stays outside of unless one of its attachments is on that node or on a node under
    /// it (formats/collider_exemption.h). The exported shape is the starting
    /// state (no push-out at load). Throws UnreadableFile, DescriptorError (file + JSON
    /// pointer) or chaintube::Error naming the file for malformed or inconsistent input.
    static HoseRuntime load(const std::filesystem::path& file, RuntimeLoadReport* report = nullptr);

    /// load() from bytes in memory: the same checks and the same runtime, messages prefixed with
    /// source.name. Buffers are needed only for collider meshes; a needed buffer that was not
    /// given is an Error naming it. The bytes are copied: they may be freed after the call.
    static HoseRuntime loadFromMemory(const ExportInMemory& source,
                                      RuntimeLoadReport* report = nullptr);

    /// For a platform that parses glTF itself: the descriptor, the glTF's nodes (index order,
    /// parents, local transforms) and, per descriptor collider (same order), its node's mesh.
    /// Throws as load() does; also when colliderMeshes does not match descriptor.colliders.
    static HoseRuntime fromDescriptor(HoseRigDescriptor descriptor, std::vector<RigNode> nodes,
                                      RuntimeLoadReport* report = nullptr,
                                      const std::vector<ColliderMesh>& colliderMeshes = {});

    /// The collider of a node, placed in the world: the node's world scale (and shear) baked
    /// into the vertices, the rigid part of `nodeWorld` (world ← node) as its frame. Throws
    /// InvalidArgument for an empty or inconsistent mesh. The runtime builds its colliders so.
    static std::shared_ptr<MeshCollider> buildCollider(const ColliderMesh& mesh,
                                                       const Eigen::Matrix4d& nodeWorld);
    /// The colliders, in descriptor order (their frames follow setNodeTransform).
    const std::vector<std::shared_ptr<MeshCollider>>& colliders() const { return m_colliders; }

    int hoseCount() const { return static_cast<int>(m_hoses.size()); }
    /// Index of the hose with this descriptor id, or −1.
    int findHose(std::string_view id) const;
    /// The hose's descriptor entry. After a cut() or a reel() its per-point arrays (axis, rest
    /// lengths, joint limits, attachment and grabbable points) describe the hose as it was then;
    /// jointNodes stays the skin's joint list (one per point until the hose is reeled).
    const RigHose& description(int hose) const
    {
        return m_descriptor.hoses.at(static_cast<size_t>(hose));
    }
    const Hose& hose(int hose) const { return m_hoses.at(static_cast<size_t>(hose)).hose; }
    /// The hose's surface as of the last update() (positions relative to hose(h).origin()).
    const HoseSurface& surface(int hose) const
    {
        return m_hoses.at(static_cast<size_t>(hose)).surface;
    }
    const HoseRigDescriptor& descriptor() const { return m_descriptor; }
    /// Clip `clip` of a hose (descriptor order: description(hose).clips) as the hose holds it
    /// now, after the last setNodeTransform or grab: the segment first … last through it, its
    /// slide (rest arc length from point 0 to the centre, metres) and frame (world centre
    /// frame.apply(clipCentre), world axis frame.rotation · clipAxis). Throws std::out_of_range
    /// for an index out of range.
    const Hose::Attachment& clip(int hose, int clip) const;

    /// A socket of the descriptor (read-only) where it is now.
    struct SocketPose
    {
        const RigSocket* description = nullptr; ///< id, node, tag, capture radius and angle
        Vec3 position = Vec3::Zero();           ///< world metres, after the last setNodeTransform
        Vec3 axis = Vec3::UnitY();              ///< world, unit
    };
    int socketCount() const { return static_cast<int>(m_descriptor.sockets.size()); }
    /// Socket `index` (descriptor order): its position and axis carried by its node's current
    /// rigid world frame (world coordinates when its node is −1). Throws std::out_of_range for
    /// an index out of range.
    SocketPose socket(int index) const;
    /// Index of the socket with this descriptor id, or −1.
    int findSocket(std::string_view id) const;

    int nodeCount() const { return static_cast<int>(m_nodes.size()); }
    const RigNode& node(int index) const { return m_nodes.at(static_cast<size_t>(index)); }
    /// Index of the first node with this name, or −1.
    int findNode(std::string_view name) const;
    /// Rigid part of the node's current world transform.
    Frame nodeWorldFrame(int node) const;

    /// A scene object moved: sets node's local transform (glTF parent space), moves the
    /// colliders on this node or a descendant (MeshCollider::setFrame), and moves every
    /// attachment on this node or a descendant, one Hose::moveAttachments() per affected hose;
    /// a hose with a moved collider and no moved attachment gets Hose::resolveCollisions().
    /// Returns the affected hoses' results (look at status). A node index out of range or a
    /// non-finite transform returns one entry with hose −1 and Status::InvalidInput, and
    /// changes nothing. The transform the node has (the same numbers, its rotation normalised)
    /// changes nothing and returns no entry: a platform may send a still part every frame, and
    /// a gravity hose comes to rest.
    [[nodiscard]] std::vector<HoseUpdate> setNodeTransform(int node, const NodeTransform& local);

    /// Moves free axis point `point` of hose `hose` to `target` (world metres); the hose
    /// follows (Hose::grab). Out-of-range indices give Status::InvalidInput; so does a point
    /// that is not in grabbablePoints or that a clip holds now.
    UpdateResult grab(int hose, int point, const Vec3& target);

    /// Cuts a running hose in two at axis point `point` (1 … pointCount − 2; chaintube/cut.h):
    /// the hose keeps its index and points 0 … point, a new hose (index hoseCount() before the
    /// call, its descriptor id "<id>~<index>") gets points point … n − 1; each starts at rest with
    /// a free end at the cut (with gravity it falls from the next update()). Each attachment and
    /// clip goes with the piece it lies on (renumbered in its piece, in the order they had; a
    /// detached one with the piece its points are on); no point is held after the cut. The
    /// skinned mesh stays one mesh with the same joints: the hose cut poses joints 0 … point, the
    /// new hose points point + 1 … n − 1 (description(newHose).jointNodes starts with −1: the
    /// cut point's joint stays with the first piece). The mesh's segment across the cut then
    /// stretches between the two cut ends; a platform that wants two clean ends draws the two
    /// pieces' own surfaces (surface(), each closed with its caps) instead, or hides that
    /// segment. Surfaces, joint poses and pulls are brought up to date at once. Refused with
    /// Status::InvalidInput, nothing changed and *why saying why: a hose index out of range, a
    /// static hose, a point at an end or out of range, a point an attachment fixes or on a
    /// clip's segment.
    CutResult cut(int hose, int point, std::string* why = nullptr);

    /// Lets go of the hose's held point (Hose::releaseGrab): with gravity it falls again on the
    /// next update(). A held point on a free end segment (points 0, 1 or the last two) within a
    /// free socket's capture — its end point within captureRadius of the socket, the end
    /// segment (out of the hose) within captureAngle of the way into it (−axis) — whose tag is
    /// the end's plug tag snaps in there: plug() into the nearest such socket (result.socket;
    /// −1 when none caught it). Refused (InvalidInput, nothing changed) for a hose index out of
    /// range.
    [[nodiscard]] PlugResult release(int hose);

    /// Advances every hose with gravity by one Hose::step() (a settled hose costs one
    /// comparison), then brings every changed hose's surface and joint poses up to date.
    /// Closes the frame (frameResult). Returns how many hoses were recomputed. update() is a
    /// frame of 1/90 s: update(Gravity::kFrameSeconds).
    int update();
    /// update() for a frame of `seconds` (the time since the last update, in (0,
    /// Gravity::kMaxFrameSeconds] = (0, 0.1]): gravity advances by that time
    /// (Hose::step(seconds)), so the same timed moves give the same hoses at any frame rate.
    /// A plug easing into its socket goes by the same time (kSnapSeconds). Throws
    /// InvalidArgument, nothing changed, for a non-finite time, ≤ 0 or above 0.1 s (a platform
    /// clamps a long hitch to 0.1 s).
    int update(double seconds);

    /// What happened to a hose in the frame the last update() closed: every setNodeTransform,
    /// grab and gravity step since the update() before it, combined: the worst status (Ok <
    /// Clamped < Infeasible), the largest violations, grab error, penetration and contact
    /// count, blocked if any was, movedPoints and iterations summed, pending and remaining as
    /// the update() left the hose. Rejected calls (InvalidInput) are not in it: they changed
    /// nothing. All Ok and 0 when nothing touched the hose in that frame.
    const UpdateResult& frameResult(int hose) const
    {
        return m_hoses.at(static_cast<size_t>(hose)).frameResult;
    }

    /// Joint poses of a hose, in axis order, as of the last update(): one per entry of
    /// description(hose).jointNodes, a count that never changes (a reeled hose's joints are
    /// placed by rest arc length: reel()). Local poses are relative to the joint node's current
    /// parent world transform. Empty for a static hose (a plain mesh that its attachment node
    /// carries; hose() and worldPositions() still follow it).
    const std::vector<JointPose>& jointPoses(int hose) const
    {
        return m_hoses.at(static_cast<size_t>(hose)).poses;
    }

    /// Attachments of a hose: the descriptor's (description(hose).attachments, in that order),
    /// then those attachEnd() made; a detached one keeps its index. Clips are not among them.
    /// 0 for a hose index out of range.
    int attachmentCount(int hose) const;
    /// Attachment `attachment` of a hose (0 … attachmentCount(hose) − 1) as it is now. Throws
    /// std::out_of_range for an index out of range.
    const LiveAttachment& attachment(int hose, int attachment) const;
    /// The axis points grab() accepts now, ascending: every point no attachment fixes (none for
    /// a static hose); description(hose).grabbablePoints until an end is detached or attached.
    /// Throws std::out_of_range for a hose index out of range.
    const std::vector<int>& grabbablePoints(int hose) const;

    /// Lets go of attachment `attachment` of a hose (an end unplugged): its points become free
    /// and grabbable; with gravity they fall from the next update() (a hose with nothing fixed
    /// and nothing held stays where it is). The attachment keeps its index (attached false, its
    /// pull zero). The part it was fixed to stays exempt from collision with the hose (the end
    /// starts inside it; formats/collider_exemption.h), as every part it is attached to.
    /// Refused with Status::InvalidInput, nothing changed and *why (when given) saying why: a
    /// hose or attachment index out of range, an attachment already detached, a static hose.
    UpdateResult detachEnd(int hose, int attachment, std::string* why = nullptr);

    /// Fixes an end segment of a hose (end 0: points 0 and 1; end 1: the last two) to `node`
    /// (−1: the world) at `localFrame`, relative to the rigid part of the node's world
    /// transform: the end point goes to the frame's origin and the end segment along its +z,
    /// pointing out of the hose (into the coupling); the frame's turn about z is the ring's
    /// alignment (only torsion sees it). The end goes there in this call as a moved attachment
    /// does (Hose::moveAttachment: a long move is made in halves and every segment stays in its
    /// band); a frame beyond the hose's reach leaves the end short of it (Status::Infeasible,
    /// Hose::attachmentGap), met once the node brings it within reach. A held point on the end
    /// segment is let go (the hand hands the end over). The new attachment follows
    /// setNodeTransform of the node; its index, attachmentCount(hose) − 1, goes to *attachment.
    /// Refused with Status::InvalidInput, nothing changed and *why saying why: a hose or node
    /// index out of range, a static hose, an end other than 0 or 1, a non-finite frame or a
    /// rotation of length 0.5 or less (it is normalised), an end segment that an attachment or
    /// a clip holds now.
    UpdateResult attachEnd(int hose, int end, int node, const Frame& localFrame,
                           int* attachment = nullptr, std::string* why = nullptr);

    /// How hard the hose pulls on attachment `attachment` (0 … attachmentCount(hose) − 1) as of
    /// the last update() (chaintube/tension.h): the world direction, tautness 0 … 1, strain and
    /// the pull per unit axial stiffness. The descriptor carries no axial stiffness: a platform
    /// that wants newtons passes its hose's EA (N per unit strain) to AttachmentPull::force().
    /// All zero when the hose is slack on both sides of the attachment, for a detached one, and
    /// for one attached since the last update(). Throws std::out_of_range for an index out of
    /// range.
    const AttachmentPull& attachmentPull(int hose, int attachment) const;

    // Sockets: a hose end plugged into a socket is an attachment (attachment()) on the socket's
    // node whose `socket` names it; a socket holds one end at a time.

    /// The update() time a plugged end takes to ease into its socket: five frames at 90 Hz.
    static constexpr double kSnapSeconds = 5.0 / 90.0;

    /// Plugs end `end` of a hose (0: points 0 and 1; 1: the last two) into socket `socket`: the
    /// end is fixed where it is to the socket's node, then eases onto the socket over the next
    /// kSnapSeconds of update() time, each update a share of the way left in proportion to its
    /// time (seated in five updates at 90 Hz, three at 45 Hz; the end point onto the socket's
    /// position, the end segment
    /// along −axis, into the part; its turn about the axis kept), each a moved attachment
    /// (Hose::moveAttachment: bends give way first, every segment stays in its band; a socket
    /// out of reach leaves the end short, Status::Infeasible in frameResult, met once the part
    /// brings it within reach). From then on the end follows the socket's node. A held point on
    /// the end segment is let go. Needs no capture: a platform may plug from afar. Refused with
    /// Status::InvalidInput, nothing changed and *why saying why: a hose or socket index out of
    /// range, an end other than 0 or 1, a static hose, a socket tag that is not the end's plug
    /// tag (RigHose::plugStart/plugEnd), a socket that holds an end, an end that an attachment
    /// or a clip holds now.
    [[nodiscard]] PlugResult plug(int hose, int end, int socket, std::string* why = nullptr);

    /// Unplugs end `end` of a hose: detachEnd() of the attachment that fixes it (one plug() or
    /// a snap-in made, its socket then free, or one of the export's). Refused with
    /// Status::InvalidInput, nothing changed and *why saying why: a hose index out of range, an
    /// end other than 0 or 1, a static hose, an end that no attachment fixes.
    [[nodiscard]] PlugResult unplug(int hose, int end, std::string* why = nullptr);

    /// The hose end socket `socket` holds now (hose −1 when free). Ends attached at export
    /// occupy no socket. Throws std::out_of_range for an index out of range.
    SocketOccupant socketOccupant(int socket) const;

    /// Surface vertex positions in world metres (3 floats per vertex, vertex order of
    /// SurfaceTopology), as of the last update().
    std::vector<float> worldPositions(int hose) const;

    // --- Reel in, pay out -------------------------------------------------------------------

    /// Pays out (`length` > 0, metres) or reels in (`length` < 0) hose at `end`, whose
    /// attachment is the reel's outlet (chaintube/reel.h: the length changes in the segment
    /// leaving it, points added or removed there); a frame's call is speed × frame time. The
    /// rest length stays within [minLength, maxLength]. The runtime's bookkeeping follows the
    /// points: attachment() point indices, grabbablePoints(), the held point, clips, a later
    /// cut(); description(hose) then describes the hose as it is (axis, rest lengths, joint
    /// limits, attachment points, grabbable points). The skin keeps its joints: from the first
    /// reel on, each joint follows a place on the hose by rest arc length, the joints beyond the
    /// outlet keeping their distance from the far end (the mesh slides out of and into the
    /// reel; a joint reeled in waits at the outlet, and the mesh's segment leaving the outlet
    /// spans what is paid out beyond the exported length: exporters/README.md, "Reel in, pay
    /// out"). The change shows in surface() and jointPoses() after the next update(), and is in
    /// that frame's frameResult(). Refused with Status::InvalidInput, nothing changed and
    /// `message` saying why: a hose index out of range, a static hose, an end no attachment
    /// fixes, a non-finite length or bound, minLength < 0, maxLength < minLength. A hose
    /// already outside [minLength, maxLength] moves only towards it (Clamped when asked the
    /// other way).
    ReelResult reel(int hose, HoseEnd end, double length, double minLength, double maxLength);
    /// reel() with clip `clip` of the hose (description(hose).clips order) as the reel's outlet
    /// and the drum towards `drumEnd` (reelThroughClip in chaintube/reel.h). Refused as reel(),
    /// and for a clip index out of range.
    ReelResult reelThroughClip(int hose, int clip, HoseEnd drumEnd, double length, double minLength,
                               double maxLength);

    // --- the work of a frame ------------------------------------------------------------
    /// Bounds the work of every later update of each hose (Hose::setBudget): a
    /// setNodeTransform, grab or update() does at most budget.newtonSteps Newton steps a hose
    /// and leaves it valid; what it cannot finish (pending) goes on in the next update() calls,
    /// each within the budget too, until the target is met or, where no budgeted try advances,
    /// the library lets the bends give way or the work rests (UpdateResult::pending; no update()
    /// finishes anything without the budget). UpdateBudget::realtime() from load; UpdateBudget{}
    /// lifts the bound (every update converges as far as its own limits take it). Throws
    /// InvalidArgument for newtonSteps < 0 (nothing changes).
    void setBudget(const UpdateBudget& budget);
    const UpdateBudget& budget() const { return m_budget; }
    /// The hose's last update ran out of the budget and update() goes on with it
    /// (Hose::pending()). False for a hose index out of range.
    bool pending(int hose) const;
    /// With pending(hose): how far the hose still is from its target (metres, Hose::remaining():
    /// the held point from its grab's goal, the largest gap of a moved attachment); 0 when
    /// nothing is pending or for a hose index out of range.
    double remaining(int hose) const;

private:
    /// The outlet a hose was last reeled through: an end's attachment, or a clip (index in
    /// description order) with the drum towards `end`.
    struct ReelOutlet
    {
        static constexpr int kEnd = -1;   ///< clip: the attachment fixing `end` is the outlet
        static constexpr int kNever = -2; ///< clip: never reeled (joint i is point i)
        static constexpr int kNone = -3;  ///< clip: reeled before a cut, no outlet now
        int clip = kNever;                ///< a clip index (description order), or one of the above
        HoseEnd end = HoseEnd::Start;
        bool operator==(const ReelOutlet&) const = default;
    };
    struct RunningHose
    {
        Hose hose;
        HoseSurface surface;
        std::vector<int> clipIds;         ///< the Hose attachment id per clip
        std::vector<LiveAttachment> live; ///< the attachments now (attachment())
        std::vector<int> grabbable;       ///< grabbablePoints()
        std::vector<JointPose> poses;
        std::vector<AttachmentPull> pulls; ///< per attachment, as of the last update()
        bool pullsStale = true;            ///< the pins changed without a new shape (a release)
        std::uint64_t posedRevision = 0;
        std::vector<int> jointParents;
        UpdateResult pendingResult; ///< the frame being built, since the last update()
        UpdateResult frameResult;   ///< the frame the last update() closed
        /// Reel: where the skin's joints sit once the hose was reeled (unused before: joint i
        /// is point i): rest arc length from point 0 per joint, whether it is beyond the reel's
        /// outlet (it keeps its distance from the far end) and the outlet they were split by.
        std::vector<double> jointArc;
        std::vector<char> jointBeyond;
        ReelOutlet reelOutlet;
    };
    HoseRuntime() = default;
    static void combine(UpdateResult& frame, const UpdateResult& result);
    void recomputeWorld();
    int refresh(); ///< update() without the gravity step
    void poseJoints(RunningHose& running, const RigHose& description);
    static void measurePulls(RunningHose& running);
    /// The hose's colliders: every descriptor collider that none of its attachments' (attached
    /// or not) or clips' nodes exempts (formats/collider_exemption.h).
    void chooseColliders(size_t hose);
    static void findGrabbable(RunningHose& running, const RigHose& description);
    /// The frame of a hose end now: origin its end point, z out of the hose along the end
    /// segment, x the end ring's alignment made perpendicular to z.
    static Frame endFrame(const RunningHose& running, int end);
    /// The live attachment that fixes end `end` of a hose now, or −1.
    static int attachmentAtEnd(const RunningHose& running, int end);
    /// Moves every easing plugged end `seconds` of its easing towards its socket (update()).
    void easeIntoSockets(size_t hose, double seconds);
    ReelResult reelAt(int hose, ReelOutlet outlet, double length, double minLength,
                      double maxLength);
    /// The reel's outlet point and the side (+1: higher indices) its free hose is on; point
    /// −1 when the outlet's attachment or clip is no longer on the hose.
    static std::pair<int, int> outletPoint(const RunningHose& running, const ReelOutlet& outlet,
                                           const RigHose& description);
    /// Where joint `joint` of a reeled hose is posed: rest arc length from point 0.
    static double jointPlace(const RunningHose& running, size_t joint,
                             const std::vector<double>& arcs, double outletArc, int side);

    HoseRigDescriptor m_descriptor;
    std::vector<RigNode> m_nodes;
    std::vector<Eigen::Matrix<double, 4, 4, Eigen::DontAlign>> m_world; ///< per node, world ← node
    std::vector<RunningHose> m_hoses;
    std::vector<std::shared_ptr<MeshCollider>> m_colliders; ///< per descriptor collider
    bool m_nodesMoved = false;
    UpdateBudget m_budget = UpdateBudget::realtime(); ///< setBudget()
};

} // namespace chaintube::rig
