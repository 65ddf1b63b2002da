/* ChainTube runtime, C ABI: loads an exported hose rig (glTF/GLB with its CHAINTUBE_hose_rig
 * descriptor) and runs its hoses, for platforms that bind C: Unity (P/Invoke), Unreal plugins,
 * Godot (GDExtension), WebAssembly. Library: libchaintube_runtime_c (C99; the C++ runtime
 * rig::HoseRuntime inside, linked statically). Integration guide: exporters/README.md.
 *
 * Conventions
 * - Every function except chaintube_runtime_abi_version, chaintube_status_name and
 *   chaintube_last_error returns a chaintube_status. On failure nothing changed (no output
 *   written, the rig as before) and chaintube_last_error() names the function, the argument or
 *   the file and field, and what was expected. No exception crosses this boundary.
 * - Units: metres, radians. Frames: glTF's (right-handed, +Y up). Quaternions are x, y, z, w
 *   (glTF order). A transform ("TRS", 10 numbers) is translation x, y, z; rotation x, y, z, w;
 *   scale x, y, z; a node's is relative to its parent (parent <- node = T * R * S).
 *   A rigid pose (7 numbers) is translation x, y, z; rotation x, y, z, w.
 * - Indices are 0-based. A buffer's capacity is a count of elements (floats, doubles or
 *   integers, not bytes) and must be at least what the function writes; more is fine.
 * - Ownership: a load function creates a rig, chaintube_rig_destroy frees it. Strings the rig
 *   returns (ids, names, warnings) are UTF-8, owned by the rig and valid until it is destroyed.
 *   Bytes given to a load function are copied: the caller may free them after the call.
 * - Threads: a rig is not thread-safe; call its functions from one thread at a time. Different
 *   rigs may run on different threads at once. The last-error text is per thread.
 * - A frame: chaintube_rig_set_node_transform for scene objects that moved, chaintube_rig_grab
 *   for held points, chaintube_rig_update_seconds with the frame's time (chaintube_rig_update
 *   for a 90 Hz frame), then chaintube_rig_joint_poses (skinned meshes) or
 *   chaintube_rig_surface (vertex buffers), chaintube_rig_hose_result for each hose, and
 *   chaintube_rig_attachment_pull for the parts the hoses hold back; chaintube_rig_reel before
 *   the update for a hose paid out or reeled in.
 */
#ifndef CHAINTUBE_RUNTIME_C_H
#define CHAINTUBE_RUNTIME_C_H

#include <stddef.h>
#include <stdint.h>

#if defined(_WIN32)
#if defined(CHAINTUBE_RUNTIME_C_BUILD)
#define CHAINTUBE_API __declspec(dllexport)
#else
#define CHAINTUBE_API __declspec(dllimport)
#endif
#elif defined(__GNUC__)
#define CHAINTUBE_API __attribute__((visibility("default")))
#else
#define CHAINTUBE_API
#endif

/* ABI version: a caller passes CHAINTUBE_RUNTIME_ABI_VERSION, as compiled, to the load
 * functions. A library of another major version, or of an older minor version than the
 * caller's, refuses to load (CHAINTUBE_ERROR_ABI_MISMATCH). Minor versions only add: each
 * function added after 1.0 says since which ("Since ABI 1.4": chaintube_rig_update_seconds). */
#define CHAINTUBE_RUNTIME_ABI_VERSION_MAJOR 1
#define CHAINTUBE_RUNTIME_ABI_VERSION_MINOR 4
#define CHAINTUBE_RUNTIME_ABI_VERSION                                                              \
    ((uint32_t)((CHAINTUBE_RUNTIME_ABI_VERSION_MAJOR << 16) | CHAINTUBE_RUNTIME_ABI_VERSION_MINOR))

#ifdef __cplusplus
extern "C" {
#endif

typedef enum chaintube_status {
    CHAINTUBE_OK = 0,
    CHAINTUBE_ERROR_INVALID_ARGUMENT = 1, /* a NULL pointer, NaN/Inf, a zero scale or quaternion */
    CHAINTUBE_ERROR_OUT_OF_RANGE = 2,     /* a hose, node, point or warning index */
    CHAINTUBE_ERROR_BUFFER_TOO_SMALL = 3, /* a capacity below what the call writes */
    CHAINTUBE_ERROR_NOT_FOUND = 4,        /* chaintube_rig_find_*: no such name */
    CHAINTUBE_ERROR_NOT_GRABBABLE = 5,    /* a fixed point, one a clip holds, a static hose */
    CHAINTUBE_ERROR_ABI_MISMATCH = 6,     /* the caller was built against another ABI version */
    CHAINTUBE_ERROR_UNREADABLE_FILE = 7, /* the glTF, a buffer or the sidecar: missing, no access */
    CHAINTUBE_ERROR_MALFORMED = 8,       /* glTF, GLB or descriptor malformed or inconsistent */
    CHAINTUBE_ERROR_OUT_OF_MEMORY = 9,
    CHAINTUBE_ERROR_INTERNAL = 10 /* a bug: please report the message */
} chaintube_status;

/* A hose's state after an update (chaintube_hose_result.status). */
typedef enum chaintube_hose_status {
    CHAINTUBE_HOSE_OK = 0,        /* every request met, every constraint holds */
    CHAINTUBE_HOSE_CLAMPED = 1,   /* a grab target was out of reach; every constraint holds */
    CHAINTUBE_HOSE_INFEASIBLE = 2 /* attachments contradict each other; violations reported */
} chaintube_hose_status;

/* An opaque loaded rig. */
typedef struct chaintube_rig chaintube_rig;

/* Bytes held by the caller (a glTF buffer). */
typedef struct chaintube_bytes
{
    const void* data;
    size_t size;
} chaintube_bytes;

/* One hose of the rig (chaintube_rig_hose_info). */
typedef struct chaintube_hose_info
{
    const char* id;          /* the descriptor's id, unique in the rig (chaintube_rig_find_hose) */
    const char* name;        /* display name */
    double rest_length;      /* metres: the sum of the segments' rest lengths */
    double outer_radius;     /* metres: half the outer diameter */
    int32_t point_count;     /* axis points (= rings), >= 2 */
    int32_t joint_count;     /* poses written by chaintube_rig_joint_poses: point_count, or 0
                                for a static hose (a plain mesh that its node carries) */
    int32_t grabbable_count; /* free axis points (chaintube_rig_grabbable_points) */
    int32_t vertex_count;    /* surface vertices (chaintube_rig_surface) */
    int32_t index_count;     /* triangle indices, 3 per triangle (chaintube_rig_surface_topology) */
    int32_t mesh_node;       /* glTF node carrying the hose's mesh */
    int32_t skin;            /* glTF skin of the mesh, -1 for a static hose */
    int32_t is_static;       /* 1: every point is fixed to one node; the hose never deforms */
    int32_t has_gravity;     /* 1: the hose sags under gravity on every update */
    int32_t has_torsion;     /* 1: turning an attachment about the axis twists the rings */
} chaintube_hose_info;

/* One glTF node (chaintube_rig_node_info). */
typedef struct chaintube_node_info
{
    const char* name; /* "" when the glTF gives none */
    int32_t parent;   /* parent node index, -1 at the scene root */
} chaintube_node_info;

/* What happened to a hose (chaintube_rig_grab, chaintube_rig_hose_result). */
typedef struct chaintube_hose_result
{
    int32_t status;          /* chaintube_hose_status */
    int32_t blocked;         /* 1: a collider kept the request from being met */
    double length_violation; /* largest segment length beyond the stretch band, relative to
                                its rest length; 0 = none */
    double angle_violation;  /* radians beyond a joint's bend limit; 0 = none */
    double grab_error;       /* metres between a grab's target and where the point ended */
    double penetration;      /* metres the hose is inside a collider; 0 = none */
    int32_t moved_points;    /* axis points that moved */
    int32_t contacts;        /* axis points touching a collider */
} chaintube_hose_result;

/* One clip of a hose (chaintube_rig_clip_info): a guide on a scene object that the hose passes
 * through along the clip's axis and slides through when the object moves or a hand pulls; no
 * rest length changes (exporters/README.md, "Clips"). The segment through the clip is held on
 * the axis, its two points at their rest distances from the centre: neither can be grabbed
 * while held. Since ABI 1.1. */
typedef struct chaintube_clip_info
{
    double centre[3]; /* world metres: the clip's centre, where its node puts it now */
    double axis[3];   /* world, unit: the clip's axis, pointing towards the hose's last point */
    double slide;     /* metres of rest length from point 0 to the centre */
    double slide_min; /* end stops of slide, metres (slide_max <= the hose's rest_length) */
    double slide_max;
    double gap;      /* metres the held points are from where the clip holds them: 0 while met */
    int32_t node;    /* glTF node carrying the clip, -1: fixed in the world */
    int32_t segment; /* the segment through the clip: points segment and segment + 1 */
    int32_t turning; /* 1: sliding-turning (the hose may also turn about the clip's axis) */
} chaintube_clip_info;

/* A hose's pull on one of its attachments after the last chaintube_rig_update
 * (chaintube_rig_attachment_pull). The model has no forces: the pull comes from the shape. Each
 * side of the attachment whose free span ends at another pinned point (an attachment, a clip,
 * the held point) is taut as its chord c nears its rest length L: tautness 0 while
 * c <= 0.98 L, rising linearly to 1 at c = L (1 while an attachment is out of reach); a side
 * ending at a free end is slack. Since ABI 1.2. */
typedef struct chaintube_attachment_pull
{
    double direction[3]; /* world, unit: the way the hose draws the attachment's part (its taut
                            sides along their first free segments); 0, 0, 0 when slack */
    double tautness;     /* 0 (slack) ... 1 (drawn straight), the largest of its sides */
    double strain;       /* >= 0: how far the taut span is stretched beyond its rest length,
                            relative (0 for a hose drawn straight but not stretched) */
    double force[3];     /* world newtons for the axial_stiffness passed: the sides'
                            tautness * EA * strain along their pulls, summed; 0 when slack */
    int32_t node;        /* glTF node the attachment is on, -1: fixed in the world */
    int32_t first_point; /* the axis points it fixes, first ... last */
    int32_t last_point;
    int32_t attached; /* 1 while attached; 0 once chaintube_rig_detach_end let go of it */
} chaintube_attachment_pull;

/* A socket of the rig (chaintube_rig_socket_info): a coupling on a part that a hose end plugs
 * into; it holds one end at a time. Since ABI 1.3. */
typedef struct chaintube_socket_info
{
    const char* id;        /* the descriptor's id, unique in the rig (chaintube_rig_find_socket) */
    const char* tag;       /* the plug tag of the hose ends it takes */
    double position[3];    /* world metres: where its node puts it now */
    double axis[3];        /* world, unit: the direction out of the part (a plugged end
                              segment points along -axis, into the part) */
    double capture_radius; /* metres: a released end point this near may snap in */
    double capture_angle;  /* radians: ... with its end segment this near -axis */
    int32_t node;          /* glTF node carrying it, -1: fixed in the world */
    int32_t occupant_hose; /* the hose whose end it holds, -1: free */
    int32_t occupant_end;  /* that end: 0 (the first point's) or 1 (the last point's); -1 */
    int32_t occupant_attachment; /* the hose's attachment holding it; -1 */
} chaintube_socket_info;

/* The library's ABI version (CHAINTUBE_RUNTIME_ABI_VERSION of its build). */
CHAINTUBE_API uint32_t chaintube_runtime_abi_version(void);

/* The enumerator's name ("CHAINTUBE_ERROR_BUFFER_TOO_SMALL"); "unknown status" otherwise.
 * A static string. */
CHAINTUBE_API const char* chaintube_status_name(chaintube_status status);

/* What the last failing call on this thread got wrong, "" if none failed yet. Owned by the
 * library; valid until the next failing call on this thread. Successful calls leave it. */
CHAINTUBE_API const char* chaintube_last_error(void);

/* Loads an exported .glb, or .gltf with its buffers beside it; the descriptor comes from the
 * CHAINTUBE_hose_rig extension, or from <name>.hoses.json beside the file when the glTF has
 * none (a warning says so). path: UTF-8. abi_version: CHAINTUBE_RUNTIME_ABI_VERSION.
 * On success *rig is a new rig (free it with chaintube_rig_destroy); on failure *rig is not
 * written. The hoses start as exported. */
CHAINTUBE_API chaintube_status chaintube_rig_load_file(uint32_t abi_version, const char* path,
                                                       chaintube_rig** rig);

/* chaintube_rig_load_file from memory. gltf: the .glb bytes or the .gltf JSON text (gltf_size
 * bytes). buffers[i] (buffer_count entries): the bytes of the glTF's buffer i when it has a
 * uri (a .gltf's .bin); an entry for a GLB's BIN chunk is not read and may be {NULL, 0};
 * buffers may be NULL when buffer_count is 0. Buffers are read only for collider meshes; one
 * that is needed and not given is an error naming it. sidecar: the <name>.hoses.json text,
 * used only when the glTF has no extension; may be NULL (sidecar_size 0). name: names the
 * export in messages and warnings ("rig.glb"); NULL gives "<memory>". Everything is copied. */
CHAINTUBE_API chaintube_status chaintube_rig_load_memory(uint32_t abi_version, const char* name,
                                                         const void* gltf, size_t gltf_size,
                                                         const chaintube_bytes* buffers,
                                                         int32_t buffer_count, const void* sidecar,
                                                         size_t sidecar_size, chaintube_rig** rig);

/* Frees a rig and every string it returned. NULL is accepted and does nothing (CHAINTUBE_OK). */
CHAINTUBE_API chaintube_status chaintube_rig_destroy(chaintube_rig* rig);

/* The load report's warnings (e.g. the descriptor came from the sidecar; a hose was exported
 * stretched): *count of them, and warning `index` in [0, count). */
CHAINTUBE_API chaintube_status chaintube_rig_warning_count(const chaintube_rig* rig,
                                                           int32_t* count);
CHAINTUBE_API chaintube_status chaintube_rig_warning(const chaintube_rig* rig, int32_t index,
                                                     const char** text);

/* Number of hoses and of glTF nodes. Hose indices are in descriptor order, node indices the
 * glTF's. */
CHAINTUBE_API chaintube_status chaintube_rig_hose_count(const chaintube_rig* rig, int32_t* count);
CHAINTUBE_API chaintube_status chaintube_rig_node_count(const chaintube_rig* rig, int32_t* count);

/* Index of the hose with descriptor id `id`, or of the first node named `name` (UTF-8).
 * CHAINTUBE_ERROR_NOT_FOUND when there is none (the index is not written). */
CHAINTUBE_API chaintube_status chaintube_rig_find_hose(const chaintube_rig* rig, const char* id,
                                                       int32_t* hose);
CHAINTUBE_API chaintube_status chaintube_rig_find_node(const chaintube_rig* rig, const char* name,
                                                       int32_t* node);

/* A hose's properties. */
CHAINTUBE_API chaintube_status chaintube_rig_hose_info(const chaintube_rig* rig, int32_t hose,
                                                       chaintube_hose_info* info);

/* The axis points chaintube_rig_grab accepts for a hose, ascending: every point no attachment
 * fixes (a point a clip holds is among them, refused only while the clip holds it: see
 * chaintube_rig_clip_info). Writes grabbable_count integers; capacity >= grabbable_count
 * (points may be NULL when it is 0). Detaching and attaching ends changes them. */
CHAINTUBE_API chaintube_status chaintube_rig_grabbable_points(const chaintube_rig* rig,
                                                              int32_t hose, int32_t* points,
                                                              int32_t capacity);

/* The glTF node of each joint of a hose, in axis order: joint_count integers (none for a
 * static hose); capacity >= joint_count. -1 for a joint no node takes (the first of a hose cut
 * off by chaintube_rig_cut). */
CHAINTUBE_API chaintube_status chaintube_rig_joint_nodes(const chaintube_rig* rig, int32_t hose,
                                                         int32_t* nodes, int32_t capacity);

/* A hose's rest lengths and stretch band. rest_lengths: point_count - 1 doubles (metres;
 * segment i joins points i and i + 1), capacity >= point_count - 1; *expansion_coefficient:
 * the band e, each segment's length stays within rest (1 - e) ... rest (1 + e) after every
 * update that is not INFEASIBLE. Either may be NULL, not both. Rest lengths change only where
 * chaintube_rig_reel pays a hose out or reels it in. Since ABI 1.1. */
CHAINTUBE_API chaintube_status chaintube_rig_rest_lengths(const chaintube_rig* rig, int32_t hose,
                                                          double* rest_lengths, int32_t capacity,
                                                          double* expansion_coefficient);

/* Number of clips of a hose (0 for most), and clip `clip` in [0, count) as the hose holds it
 * now: node moves and grabs slide the hose through its clips at once (the joint poses show
 * it after the next chaintube_rig_update). Clips are in the descriptor's order. Since ABI 1.1. */
CHAINTUBE_API chaintube_status chaintube_rig_clip_count(const chaintube_rig* rig, int32_t hose,
                                                        int32_t* count);
CHAINTUBE_API chaintube_status chaintube_rig_clip_info(const chaintube_rig* rig, int32_t hose,
                                                       int32_t clip, chaintube_clip_info* info);

/* Number of attachments of a hose (the descriptor's, in its order, then those
 * chaintube_rig_attach_end made; a detached one keeps its index; clips are not among them),
 * and how hard the hose pulls on attachment `attachment` in [0, count) as of the last
 * chaintube_rig_update. axial_stiffness: the hose's EA in newtons per unit strain (a rubber
 * hose of 20 mm about 1e4, a steel-braided one 1e6), finite and >= 0; the descriptor does
 * not carry one, so the platform states it (0 gives force 0 and the rest as usual). Since
 * ABI 1.2. */
CHAINTUBE_API chaintube_status chaintube_rig_attachment_count(const chaintube_rig* rig,
                                                              int32_t hose, int32_t* count);
CHAINTUBE_API chaintube_status chaintube_rig_attachment_pull(const chaintube_rig* rig, int32_t hose,
                                                             int32_t attachment,
                                                             double axial_stiffness,
                                                             chaintube_attachment_pull* pull);

/* A node's name and parent. */
CHAINTUBE_API chaintube_status chaintube_rig_node_info(const chaintube_rig* rig, int32_t node,
                                                       chaintube_node_info* info);

/* A node's current local transform: trs[10] (TRS, relative to its parent). */
CHAINTUBE_API chaintube_status chaintube_rig_node_transform(const chaintube_rig* rig, int32_t node,
                                                            double trs[10]);

/* A scene object moved: sets node's local transform trs[10] (TRS, relative to its parent; the
 * rotation need not be exactly unit, it is normalised) and moves every attachment and collider
 * on that node or under it; the hoses follow. Refused: a non-finite number, a rotation of
 * length 0.5 or less, a zero scale. The hoses' outcome is in chaintube_rig_hose_result after the
 * next chaintube_rig_update. */
CHAINTUBE_API chaintube_status chaintube_rig_set_node_transform(chaintube_rig* rig, int32_t node,
                                                                const double trs[10]);

/* Moves axis point `point` of a hose to target[3] (world metres); the hose follows, the point
 * is held there until chaintube_rig_release or a grab of another point. An unreachable target
 * is not an error: the point goes as far as the hose allows (status CLAMPED, grab_error).
 * The point must be one of chaintube_rig_grabbable_points and not held by a clip now (else
 * CHAINTUBE_ERROR_NOT_GRABBABLE). result (may be NULL) receives this grab's outcome. */
CHAINTUBE_API chaintube_status chaintube_rig_grab(chaintube_rig* rig, int32_t hose, int32_t point,
                                                  const double target[3],
                                                  chaintube_hose_result* result);

/* Unplugs an end: lets go of attachment `attachment` of a hose (chaintube_rig_attachment_count).
 * Its points become free and grabbable (chaintube_rig_grabbable_points, hose_info's
 * grabbable_count); with gravity they fall from the next update (a hose with nothing fixed and
 * nothing held stays where it is). It keeps its index, attached 0. The part it was fixed to
 * stays exempt from collision with the hose (the end starts inside it). result (may be NULL): this
 * call's outcome. Refused (CHAINTUBE_ERROR_INVALID_ARGUMENT, nothing changed): an attachment
 * already detached, a static hose. Since ABI 1.2. */
CHAINTUBE_API chaintube_status chaintube_rig_detach_end(chaintube_rig* rig, int32_t hose,
                                                        int32_t attachment,
                                                        chaintube_hose_result* result);

/* Plugs an end: fixes end `end` of a hose (0: points 0 and 1; 1: the last two) to `node` (-1:
 * the world) at pose[7] (rigid pose relative to the node: translation, rotation x y z w): the
 * end point goes to the pose's origin and the end segment along its +z, out of the hose (into
 * the coupling). The end goes there in this call, every segment within its band (a long move
 * is made in halves); a pose out of the hose's reach leaves the end short of it (status
 * INFEASIBLE), met once the node brings it within reach. A held point on the end segment is let
 * go. The new attachment follows chaintube_rig_set_node_transform of the node; *attachment
 * (may be NULL) receives its index, the new chaintube_rig_attachment_count - 1. result (may be
 * NULL): this call's outcome. Refused (nothing changed): end not 0 or 1, a non-finite pose, a
 * rotation of length 0.5 or less (INVALID_ARGUMENT); a node out of range (OUT_OF_RANGE); an end
 * an attachment or a clip holds now, a static hose (INVALID_ARGUMENT). Since ABI 1.2. */
CHAINTUBE_API chaintube_status chaintube_rig_attach_end(chaintube_rig* rig, int32_t hose,
                                                        int32_t end, int32_t node,
                                                        const double pose[7], int32_t* attachment,
                                                        chaintube_hose_result* result);

/* Cuts a hose in two at axis point `point` (1 ... point_count - 2): the hose keeps its index
 * and points 0 ... point; a new hose, *new_hose (may be NULL; the hose count before the call),
 * gets points point ... point_count - 1 (id "<id>~<index>"). Each piece has a free end at the cut
 * and starts at rest (with gravity it falls from the next update); each attachment and clip goes
 * with the piece it lies on (renumbered in its piece); no point is held. The skinned mesh stays
 * valid with the same skin and joint list: the hose cut poses joints 0 ... point, the new hose
 * the joints beyond (chaintube_rig_joint_nodes of the new hose starts with -1, the cut point's
 * joint staying with the first piece: write the poses of the joints whose node is not -1). The
 * mesh's segment across the cut stretches between the two cut ends; a platform wanting two clean
 * ends draws each piece's own surface (chaintube_rig_surface, closed with caps). Joint poses,
 * surfaces and pulls are up to date at once. Refused (nothing changed): a point out of range
 * (OUT_OF_RANGE); a point at an end, one an attachment fixes or on a clip's segment, a static
 * hose (INVALID_ARGUMENT). Hose ids and names returned before stay valid. Since ABI 1.2. */
CHAINTUBE_API chaintube_status chaintube_rig_cut(chaintube_rig* rig, int32_t hose, int32_t point,
                                                 int32_t* new_hose);

/* Lets go of the hose's held point; with gravity it falls again from the next update. A held
 * point on a free end segment within a free socket's capture whose tag is the end's plug tag
 * snaps in there (chaintube_rig_release_snap, which also says where). */
CHAINTUBE_API chaintube_status chaintube_rig_release(chaintube_rig* rig, int32_t hose);

/* Sockets (since ABI 1.3). A hose end in a socket is an attachment on the socket's node
 * (chaintube_rig_attachment_count and _pull list it); a socket holds one end at a time; ends
 * attached at export occupy no socket. */

/* Number of sockets (descriptor order), and the index of the socket with id `id`
 * (CHAINTUBE_ERROR_NOT_FOUND when there is none; the index is not written). */
CHAINTUBE_API chaintube_status chaintube_rig_socket_count(const chaintube_rig* rig, int32_t* count);
CHAINTUBE_API chaintube_status chaintube_rig_find_socket(const chaintube_rig* rig, const char* id,
                                                         int32_t* socket);

/* Socket `socket` in [0, count) now: where its node puts it and which end it holds. */
CHAINTUBE_API chaintube_status chaintube_rig_socket_info(const chaintube_rig* rig, int32_t socket,
                                                         chaintube_socket_info* info);

/* chaintube_rig_release, and *socket (may be NULL) receives the socket the end snapped into,
 * -1 when none caught it (or no point was held). A socket catches the end when its end point is
 * within capture_radius, its end segment (out of the hose) within capture_angle of -axis, the
 * socket is free and its tag is the end's plug tag; the nearest such socket wins. The end then
 * eases in as after chaintube_rig_plug. */
CHAINTUBE_API chaintube_status chaintube_rig_release_snap(chaintube_rig* rig, int32_t hose,
                                                          int32_t* socket);

/* Plugs end `end` of a hose (0: points 0 and 1; 1: the last two) into socket `socket`: the end
 * is fixed where it is to the socket's node and eases onto the socket over the next 5
 * chaintube_rig_update calls (end point onto position, end segment along -axis), each frame
 * every segment in its band; then it follows the socket's node. No capture needed. A held
 * point on the end segment is let go. *attachment (may be NULL): the new attachment's index.
 * Refused (nothing changed): a socket out of range (OUT_OF_RANGE); end not 0 or 1, a static
 * hose, a socket whose tag is not the end's plug tag, a socket that holds an end, an end that
 * an attachment or a clip holds now (INVALID_ARGUMENT). */
CHAINTUBE_API chaintube_status chaintube_rig_plug(chaintube_rig* rig, int32_t hose, int32_t end,
                                                  int32_t socket, int32_t* attachment);

/* Unplugs end `end` of a hose: chaintube_rig_detach_end of the attachment that fixes it (in a
 * socket, which is then free, or one of the export's). *socket (may be NULL): the socket it
 * left, -1 for none. Refused (nothing changed, INVALID_ARGUMENT): end not 0 or 1, a static
 * hose, an end no attachment fixes. */
CHAINTUBE_API chaintube_status chaintube_rig_unplug(chaintube_rig* rig, int32_t hose, int32_t end,
                                                    int32_t* socket);

/* Ends a frame of 1/90 s: steps every hose with gravity (bounded work; a settled hose costs one
 * comparison), then brings the changed hoses' joint poses and surfaces up to date.
 * recomputed (may be NULL): how many hoses changed. Another frame rate:
 * chaintube_rig_update_seconds. */
CHAINTUBE_API chaintube_status chaintube_rig_update(chaintube_rig* rig, int32_t* recomputed);

/* chaintube_rig_update for a frame of `seconds` (the time since the last update, in (0, 0.1]):
 * gravity advances by that time in steps of at most 1/90 s, so the same timed moves give the
 * same hoses at 45, 72, 90 or 120 Hz; chaintube_rig_update is a frame of 1/90 s. Clamp a
 * longer hitch to 0.1 s. A non-finite time, <= 0 or above 0.1: CHAINTUBE_ERROR_INVALID_ARGUMENT,
 * nothing changes. Since ABI 1.4. */
CHAINTUBE_API chaintube_status chaintube_rig_update_seconds(chaintube_rig* rig, double seconds,
                                                            int32_t* recomputed);

/* What happened to a hose in the frame the last chaintube_rig_update ended: its node moves,
 * grabs and gravity step combined (the worst status, the largest violations, grab error,
 * penetration and contacts, blocked if any was, moved points summed). All 0 (OK) when nothing
 * touched the hose. Refused calls are not in it: they changed nothing. */
CHAINTUBE_API chaintube_status chaintube_rig_hose_result(const chaintube_rig* rig, int32_t hose,
                                                         chaintube_hose_result* result);

/* Joint poses of a hose as of the last update, in axis order (joint_count joints; none for a
 * static hose). local: 10 floats per joint, the TRS to write into the joint node (relative to
 * its glTF parent's current world transform); world: 7 per joint, the rigid world pose (ring
 * centre; rotation with columns ring alignment, binormal, tangent). Either may be NULL to skip
 * it, not both; capacities in floats: >= 10 * joint_count and >= 7 * joint_count. */
CHAINTUBE_API chaintube_status chaintube_rig_joint_poses(const chaintube_rig* rig, int32_t hose,
                                                         float* local, int32_t local_capacity,
                                                         float* world, int32_t world_capacity);

/* chaintube_rig_joint_poses in double precision (e.g. Unreal's double transforms). */
CHAINTUBE_API chaintube_status chaintube_rig_joint_poses_f64(const chaintube_rig* rig, int32_t hose,
                                                             double* local, int32_t local_capacity,
                                                             double* world, int32_t world_capacity);

/* A hose's surface as of the last update: positions (world metres) and unit normals, 3 floats
 * per vertex (vertex_count vertices: rings, each with a seam vertex, then the two caps).
 * Either may be NULL to skip it, not both; capacities >= 3 * vertex_count. */
CHAINTUBE_API chaintube_status chaintube_rig_surface(const chaintube_rig* rig, int32_t hose,
                                                     float* positions, int32_t positions_capacity,
                                                     float* normals, int32_t normals_capacity);

/* The surface's fixed parts: indices (index_count, 3 per triangle, counter-clockwise seen from
 * outside) and uvs (2 floats per vertex: u around the profile 0..1, v along the axis in metres
 * of rest length). Either may be NULL to skip it, not both; capacities >= index_count and
 * >= 2 * vertex_count. */
CHAINTUBE_API chaintube_status chaintube_rig_surface_topology(const chaintube_rig* rig,
                                                              int32_t hose, uint32_t* indices,
                                                              int32_t indices_capacity, float* uvs,
                                                              int32_t uvs_capacity);

/* --- Reel in, pay out (since ABI 1.3) ------------------------------------------------------ */

/* What chaintube_rig_reel did. */
typedef struct chaintube_reel_result
{
    double paid;              /* metres of rest length paid out (> 0) or reeled in (< 0) */
    double rest_length;       /* metres: the hose's rest length after the call */
    double largest_move;      /* metres: a bound on how far any point moved in the call */
    const char* message;      /* "" when all was paid; else why less was (a length bound, the
                                 shape): owned by the rig, valid until it is destroyed */
    int32_t clamped;          /* 1: less than asked was paid (message says why) */
    int32_t segments_added;   /* points inserted at the outlet */
    int32_t segments_removed; /* points removed at the outlet */
    int32_t point_count;      /* the hose's axis points after the call */
} chaintube_reel_result;

/* Pays out (length > 0, metres) or reels in (length < 0) a hose where it leaves a reel: with
 * clip -1 the outlet is the attachment fixing end `end` (0: the first point, 1: the last);
 * with clip >= 0 (chaintube_rig_clip_count) it is that clip, the drum towards end `end`. A
 * frame's call is speed * frame time. The length changes in the segment leaving the outlet
 * (points added or removed there, the rest of the hose keeps its rest lengths; no point moves
 * more than twice the length paid; every segment stays in its band), and the rest length stays
 * within [min_length, max_length] (max_length may be +Inf). The point count, rest lengths,
 * grabbable points and attachment point indices change at once; joint_count never does: a
 * reeled hose's joints follow it by rest arc length, those beyond the outlet keeping their
 * distance from the far end (exporters/README.md, "Reel in, pay out"). Joint poses and the
 * surface show the change after the next chaintube_rig_update. result (may be NULL). Refused
 * (nothing changed): a hose or clip out of range (OUT_OF_RANGE); end not 0 or 1, an end no
 * attachment fixes, a static hose, a non-finite length or min_length, min_length < 0,
 * max_length NaN or below min_length (INVALID_ARGUMENT). A hose already outside the bounds
 * moves only towards them (asked away: clamped, paid 0). */
CHAINTUBE_API chaintube_status chaintube_rig_reel(chaintube_rig* rig, int32_t hose, int32_t end,
                                                  int32_t clip, double length, double min_length,
                                                  double max_length, chaintube_reel_result* result);

/* A hose's axis points as they are now (world metres, 3 doubles a point: point_count points of
 * chaintube_rig_hose_info; capacity >= 3 * point_count): the points chaintube_rig_grab and
 * chaintube_rig_cut name. Until a reel they are also the joints' positions after an update;
 * once chaintube_rig_reel changed the point count they are not. Since ABI 1.3. */
CHAINTUBE_API chaintube_status chaintube_rig_axis_points(const chaintube_rig* rig, int32_t hose,
                                                         double* points, int32_t capacity);

/* The work of a frame (since ABI 1.3). Every later node move, grab and update does at most
 * newton_steps Newton steps a hose (each O(points of the span it solves)) and leaves the hose
 * valid; what it cannot finish goes on in the next chaintube_rig_update calls, each within the
 * bound too, until met or, where no budgeted try advances it, its bends give way or it rests
 * (the hose is pending meanwhile). A rig loads with the real-time budget, 16 steps; 0 lifts the
 * bound (each update converges as far as its own limits take it). newton_steps < 0:
 * CHAINTUBE_ERROR_INVALID_ARGUMENT, nothing changes. */
CHAINTUBE_API chaintube_status chaintube_rig_set_budget(chaintube_rig* rig, int32_t newton_steps);

/* Whether a hose's last update ran out of the budget and goes on in the next update (*pending
 * 1, else 0), and how far it still is from its target (*remaining, metres: the held point from
 * where its grab goes, the largest gap of a moved attachment; 0 when nothing is pending).
 * Either may be NULL to skip it, not both. Since ABI 1.3. */
CHAINTUBE_API chaintube_status chaintube_rig_hose_pending(const chaintube_rig* rig, int32_t hose,
                                                          int32_t* pending, double* remaining);

#ifdef __cplusplus
} /* extern "C" */
#endif

#endif /* CHAINTUBE_RUNTIME_C_H */
