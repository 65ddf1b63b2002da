// C# binding of the ChainTube runtime's C ABI (chaintube/runtime_c.h), for Unity and any .NET
// or Mono program: copy this file into the project and the native library
// (libchaintube_runtime_c.so / chaintube_runtime_c.dll) where the player finds plugins.
//
// Native mirrors the header one to one (blittable structs, float/double arrays, status codes);
// Rig wraps a handle and turns a failing status into a ChainTubeException carrying the status
// and the library's message. Units, frames and buffer layouts: see the header. C# 7, no unsafe
// code; strings cross the boundary as UTF-8 bytes on every platform.
using System;
using System.Runtime.InteropServices;
using System.Text;

namespace ChainTube
{
    public enum Status : int
    {
        Ok = 0,
        InvalidArgument = 1,
        OutOfRange = 2,
        BufferTooSmall = 3,
        NotFound = 4,
        NotGrabbable = 5,
        AbiMismatch = 6,
        UnreadableFile = 7,
        Malformed = 8,
        OutOfMemory = 9,
        Internal = 10,
    }

    public enum HoseStatus : int
    {
        Ok = 0,
        Clamped = 1,
        Infeasible = 2,
    }

    [StructLayout(LayoutKind.Sequential)]
    public struct HoseInfo
    {
        public IntPtr id; // UTF-8, owned by the rig: read with Native.String
        public IntPtr name;
        public double restLength;  // metres
        public double outerRadius; // metres
        public int pointCount;
        public int jointCount; // 0 for a static hose
        public int grabbableCount;
        public int vertexCount;
        public int indexCount;
        public int meshNode;
        public int skin;
        public int isStatic;
        public int hasGravity;
        public int hasTorsion;
    }

    [StructLayout(LayoutKind.Sequential)]
    public struct NodeInfo
    {
        public IntPtr name;
        public int parent;
    }

    [StructLayout(LayoutKind.Sequential)]
    public struct HoseResult
    {
        public HoseStatus status;
        public int blocked;
        public double lengthViolation; // relative to the rest length
        public double angleViolation;  // radians
        public double grabError;       // metres
        public double penetration;     // metres
        public int movedPoints;
        public int contacts;
    }

    /// <summary>A clip of a hose (chaintube_clip_info): the hose passes through its centre along
    /// its axis and slides through it. The C struct's arrays centre[3] and axis[3] are the
    /// three doubles each.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct ClipInfo
    {
        public double centreX, centreY, centreZ; // world metres, where the clip's node puts it now
        public double axisX, axisY, axisZ;       // world, unit, towards the hose's last point
        public double slide;                     // metres of rest length from point 0 to the centre
        public double slideMin, slideMax;        // end stops of slide, metres
        public double gap;                       // metres off where the clip holds its points: 0 while met
        public int node;                         // glTF node carrying the clip, -1: the world
        public int segment;                      // held segment: points segment and segment + 1
        public int turning;                      // 1: sliding-turning
    }

    /// <summary>A hose's pull on one of its attachments after the last update
    /// (chaintube_attachment_pull): the way and how hard it draws the attachment's part, zero when
    /// slack. Since ABI 1.2.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct AttachmentPull
    {
        public double directionX, directionY, directionZ; // world, unit; 0 when slack
        public double tautness;                           // 0 (slack) ... 1 (drawn straight)
        public double strain;                             // >= 0, stretch beyond the rest length
        public double forceX, forceY, forceZ;             // world newtons for the axial stiffness passed
        public int node;                                  // glTF node of the attachment, -1: the world
        public int firstPoint, lastPoint;                 // the axis points it fixes
        public int attached;                              // 1 while attached, 0 once detached
    }

    /// <summary>A socket of the rig (chaintube_socket_info): a coupling on a part that a hose
    /// end plugs into, holding one end at a time. Since ABI 1.3.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct SocketInfo
    {
        public IntPtr id;                            // UTF-8, owned by the rig: Native.String(id)
        public IntPtr tag;                           // the plug tag of the ends it takes
        public double positionX, positionY, positionZ; // world metres, where its node puts it now
        public double axisX, axisY, axisZ;           // world, unit, out of the part
        public double captureRadius;                 // metres
        public double captureAngle;                  // radians
        public int node;                             // glTF node carrying it, -1: the world
        public int occupantHose;                     // the hose whose end it holds, -1: free
        public int occupantEnd;                      // 0 or 1; -1 when free
        public int occupantAttachment;               // the hose's attachment holding it; -1
    }

    /// <summary>What a reel call did (chaintube_reel_result). Since ABI 1.3.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct ReelResult
    {
        public double paid;            // metres paid out (> 0) or reeled in (< 0)
        public double restLength;      // metres, the hose's rest length after the call
        public double largestMove;     // metres, a bound on how far any point moved
        public IntPtr message;         // why less was paid ("" when all was): Native.String
        public int clamped;            // 1: less than asked was paid
        public int segmentsAdded, segmentsRemoved;
        public int pointCount;         // axis points after the call
        public string Message { get { return Native.String(message); } }
    }

    [StructLayout(LayoutKind.Sequential)]
    public struct Bytes
    {
        public IntPtr data;
        public UIntPtr size;
    }

    /// <summary>The C functions, as declared in chaintube/runtime_c.h.</summary>
    public static class Native
    {
        const string Library = "chaintube_runtime_c";

        /// <summary>CHAINTUBE_RUNTIME_ABI_VERSION of the header this binding was written for.</summary>
        public const uint AbiVersion = (1u << 16) | 4u;

        [DllImport(Library)] public static extern uint chaintube_runtime_abi_version();
        [DllImport(Library)] public static extern IntPtr chaintube_status_name(Status status);
        [DllImport(Library)] public static extern IntPtr chaintube_last_error();

        [DllImport(Library)]
        public static extern Status chaintube_rig_load_file(uint abiVersion, byte[] utf8Path, out IntPtr rig);
        [DllImport(Library)]
        public static extern Status chaintube_rig_load_memory(uint abiVersion, byte[] utf8Name, byte[] gltf,
            UIntPtr gltfSize, Bytes[] buffers, int bufferCount, byte[] sidecar, UIntPtr sidecarSize,
            out IntPtr rig);
        [DllImport(Library)] public static extern Status chaintube_rig_destroy(IntPtr rig);

        [DllImport(Library)] public static extern Status chaintube_rig_warning_count(IntPtr rig, out int count);
        [DllImport(Library)] public static extern Status chaintube_rig_warning(IntPtr rig, int index, out IntPtr text);
        [DllImport(Library)] public static extern Status chaintube_rig_hose_count(IntPtr rig, out int count);
        [DllImport(Library)] public static extern Status chaintube_rig_node_count(IntPtr rig, out int count);
        [DllImport(Library)] public static extern Status chaintube_rig_find_hose(IntPtr rig, byte[] utf8Id, out int hose);
        [DllImport(Library)] public static extern Status chaintube_rig_find_node(IntPtr rig, byte[] utf8Name, out int node);
        [DllImport(Library)] public static extern Status chaintube_rig_hose_info(IntPtr rig, int hose, out HoseInfo info);
        [DllImport(Library)]
        public static extern Status chaintube_rig_grabbable_points(IntPtr rig, int hose, [Out] int[] points, int capacity);
        [DllImport(Library)]
        public static extern Status chaintube_rig_joint_nodes(IntPtr rig, int hose, [Out] int[] nodes, int capacity);
        [DllImport(Library)]
        public static extern Status chaintube_rig_rest_lengths(IntPtr rig, int hose, [Out] double[] restLengths,
            int capacity, out double expansionCoefficient);
        [DllImport(Library)] public static extern Status chaintube_rig_clip_count(IntPtr rig, int hose, out int count);
        [DllImport(Library)]
        public static extern Status chaintube_rig_clip_info(IntPtr rig, int hose, int clip, out ClipInfo info);
        [DllImport(Library)]
        public static extern Status chaintube_rig_attachment_count(IntPtr rig, int hose, out int count);
        [DllImport(Library)]
        public static extern Status chaintube_rig_attachment_pull(IntPtr rig, int hose, int attachment,
            double axialStiffness, out AttachmentPull pull);
        [DllImport(Library)] public static extern Status chaintube_rig_node_info(IntPtr rig, int node, out NodeInfo info);
        [DllImport(Library)]
        public static extern Status chaintube_rig_node_transform(IntPtr rig, int node, [Out] double[] trs);
        [DllImport(Library)]
        public static extern Status chaintube_rig_set_node_transform(IntPtr rig, int node, double[] trs);
        [DllImport(Library)]
        public static extern Status chaintube_rig_grab(IntPtr rig, int hose, int point, double[] target, out HoseResult result);
        [DllImport(Library)] public static extern Status chaintube_rig_release(IntPtr rig, int hose);
        [DllImport(Library)]
        public static extern Status chaintube_rig_cut(IntPtr rig, int hose, int point, out int newHose);
        [DllImport(Library)]
        public static extern Status chaintube_rig_detach_end(IntPtr rig, int hose, int attachment, out HoseResult result);
        [DllImport(Library)]
        public static extern Status chaintube_rig_attach_end(IntPtr rig, int hose, int end, int node, double[] pose,
            out int attachment, out HoseResult result);
        // Sockets (ABI 1.3)
        [DllImport(Library)] public static extern Status chaintube_rig_socket_count(IntPtr rig, out int count);
        [DllImport(Library)]
        public static extern Status chaintube_rig_find_socket(IntPtr rig, byte[] utf8Id, out int socket);
        [DllImport(Library)]
        public static extern Status chaintube_rig_socket_info(IntPtr rig, int socket, out SocketInfo info);
        [DllImport(Library)]
        public static extern Status chaintube_rig_release_snap(IntPtr rig, int hose, out int socket);
        [DllImport(Library)]
        public static extern Status chaintube_rig_plug(IntPtr rig, int hose, int end, int socket, out int attachment);
        [DllImport(Library)]
        public static extern Status chaintube_rig_unplug(IntPtr rig, int hose, int end, out int socket);
        [DllImport(Library)]
        public static extern Status chaintube_rig_reel(IntPtr rig, int hose, int end, int clip, double length,
            double minLength, double maxLength, out ReelResult result);
        [DllImport(Library)]
        public static extern Status chaintube_rig_axis_points(IntPtr rig, int hose, [Out] double[] points, int capacity);
        [DllImport(Library)] public static extern Status chaintube_rig_update(IntPtr rig, out int recomputed);
        [DllImport(Library)]
        public static extern Status chaintube_rig_update_seconds(IntPtr rig, double seconds, out int recomputed);
        [DllImport(Library)]
        public static extern Status chaintube_rig_hose_result(IntPtr rig, int hose, out HoseResult result);
        [DllImport(Library)]
        public static extern Status chaintube_rig_joint_poses(IntPtr rig, int hose, [Out] float[] local,
            int localCapacity, [Out] float[] world, int worldCapacity);
        [DllImport(Library)]
        public static extern Status chaintube_rig_joint_poses_f64(IntPtr rig, int hose, [Out] double[] local,
            int localCapacity, [Out] double[] world, int worldCapacity);
        [DllImport(Library)]
        public static extern Status chaintube_rig_surface(IntPtr rig, int hose, [Out] float[] positions,
            int positionsCapacity, [Out] float[] normals, int normalsCapacity);
        [DllImport(Library)]
        public static extern Status chaintube_rig_surface_topology(IntPtr rig, int hose, [Out] uint[] indices,
            int indicesCapacity, [Out] float[] uvs, int uvsCapacity);

        // The work of a frame (ABI 1.3).
        [DllImport(Library)] public static extern Status chaintube_rig_set_budget(IntPtr rig, int newtonSteps);
        [DllImport(Library)]
        public static extern Status chaintube_rig_hose_pending(IntPtr rig, int hose, out int pending, out double remaining);

        /// <summary>A NUL-terminated UTF-8 string for the library.</summary>
        public static byte[] Utf8(string text)
        {
            return text == null ? null : Encoding.UTF8.GetBytes(text + "\0");
        }

        /// <summary>A string the library returned (UTF-8, NUL-terminated).</summary>
        public static string String(IntPtr text)
        {
            if (text == IntPtr.Zero) return null;
            int length = 0;
            while (Marshal.ReadByte(text, length) != 0) ++length;
            var bytes = new byte[length];
            Marshal.Copy(text, bytes, 0, length);
            return Encoding.UTF8.GetString(bytes);
        }

        public static string LastError() { return String(chaintube_last_error()); }
    }

    public class ChainTubeException : Exception
    {
        public readonly Status Status;
        public ChainTubeException(Status status, string message) : base(message) { Status = status; }
    }

    /// <summary>A loaded rig; Dispose frees it. Not thread-safe (see the header).</summary>
    public sealed class Rig : IDisposable
    {
        public IntPtr Handle { get; private set; }

        Rig(IntPtr handle) { Handle = handle; }

        static void Check(Status status)
        {
            if (status != Status.Ok) throw new ChainTubeException(status, Native.LastError());
        }

        public static Rig LoadFile(string path)
        {
            IntPtr handle;
            Check(Native.chaintube_rig_load_file(Native.AbiVersion, Native.Utf8(path), out handle));
            return new Rig(handle);
        }

        /// <summary>A .glb's bytes (e.g. a TextAsset's bytes in Unity).</summary>
        public static Rig LoadMemory(string name, byte[] glb)
        {
            IntPtr handle;
            Check(Native.chaintube_rig_load_memory(Native.AbiVersion, Native.Utf8(name), glb,
                (UIntPtr)glb.Length, null, 0, null, UIntPtr.Zero, out handle));
            return new Rig(handle);
        }

        public int HoseCount { get { int n; Check(Native.chaintube_rig_hose_count(Handle, out n)); return n; } }
        public int NodeCount { get { int n; Check(Native.chaintube_rig_node_count(Handle, out n)); return n; } }

        public int FindHose(string id) { int h; Check(Native.chaintube_rig_find_hose(Handle, Native.Utf8(id), out h)); return h; }
        public int FindNode(string name) { int n; Check(Native.chaintube_rig_find_node(Handle, Native.Utf8(name), out n)); return n; }
        public HoseInfo Info(int hose) { HoseInfo info; Check(Native.chaintube_rig_hose_info(Handle, hose, out info)); return info; }

        public int[] GrabbablePoints(int hose)
        {
            var points = new int[Info(hose).grabbableCount];
            Check(Native.chaintube_rig_grabbable_points(Handle, hose, points, points.Length));
            return points;
        }

        /// <summary>Rest length of each segment (metres; segment i joins points i and i + 1) and the
        /// stretch band e: each segment stays within rest (1 - e) ... rest (1 + e).</summary>
        public double[] RestLengths(int hose, out double expansionCoefficient)
        {
            var lengths = new double[Info(hose).pointCount - 1];
            Check(Native.chaintube_rig_rest_lengths(Handle, hose, lengths, lengths.Length, out expansionCoefficient));
            return lengths;
        }

        public int ClipCount(int hose) { int n; Check(Native.chaintube_rig_clip_count(Handle, hose, out n)); return n; }
        /// <summary>Clip `clip` as the hose holds it now (moves and grabs slide the hose at once).</summary>
        public ClipInfo Clip(int hose, int clip) { ClipInfo c; Check(Native.chaintube_rig_clip_info(Handle, hose, clip, out c)); return c; }

        public int AttachmentCount(int hose) { int n; Check(Native.chaintube_rig_attachment_count(Handle, hose, out n)); return n; }

        /// <summary>How hard the hose pulls on attachment `attachment` after the last Update: a
        /// direction, tautness 0 ... 1, and a force in newtons for the hose's axial stiffness EA
        /// (newtons per unit strain; the descriptor carries none: the platform states it).</summary>
        public AttachmentPull Pull(int hose, int attachment, double axialStiffness)
        {
            AttachmentPull pull;
            Check(Native.chaintube_rig_attachment_pull(Handle, hose, attachment, axialStiffness, out pull));
            return pull;
        }

        /// <summary>A node's current local transform: translation, rotation x y z w, scale (10 numbers).</summary>
        public double[] NodeTransform(int node)
        {
            var trs = new double[10];
            Check(Native.chaintube_rig_node_transform(Handle, node, trs));
            return trs;
        }

        /// <summary>trs: translation x, y, z; rotation x, y, z, w; scale x, y, z (glTF frame).</summary>
        public void SetNodeTransform(int node, double[] trs) { Check(Native.chaintube_rig_set_node_transform(Handle, node, trs)); }

        public HoseResult Grab(int hose, int point, double x, double y, double z)
        {
            HoseResult result;
            Check(Native.chaintube_rig_grab(Handle, hose, point, new[] { x, y, z }, out result));
            return result;
        }

        /// <summary>Lets go of the held point. A held end released in a free socket's capture
        /// whose tag fits snaps in: returns that socket, -1 when none caught it.</summary>
        public int Release(int hose) { int s; Check(Native.chaintube_rig_release_snap(Handle, hose, out s)); return s; }

        /// <summary>Cuts a hose in two at axis point `point` (1 ... pointCount - 2): the hose keeps
        /// points 0 ... point, the returned new hose the rest. The skin keeps its joints: the new
        /// hose poses those beyond the cut (its JointNodes start with -1).</summary>
        public int Cut(int hose, int point) { int h; Check(Native.chaintube_rig_cut(Handle, hose, point, out h)); return h; }

        /// <summary>Unplugs an end: lets go of attachment `attachment` (its points fall free, with
        /// gravity from the next Update). Returns this call's outcome.</summary>
        public HoseResult DetachEnd(int hose, int attachment)
        {
            HoseResult result;
            Check(Native.chaintube_rig_detach_end(Handle, hose, attachment, out result));
            return result;
        }

        /// <summary>Plugs end `end` (0: first point's, 1: last point's) into `node` (-1: the world)
        /// at pose (7 numbers relative to the node: translation, rotation x y z w; the end segment
        /// along its +z). Returns the new attachment's index; result: this call's outcome.</summary>
        public int AttachEnd(int hose, int end, int node, double[] pose, out HoseResult result)
        {
            int attachment;
            Check(Native.chaintube_rig_attach_end(Handle, hose, end, node, pose, out attachment, out result));
            return attachment;
        }

        // Sockets (ABI 1.3): a plugged end is an attachment on the socket's node (AttachmentCount,
        // Pull list it); a socket holds one end at a time.
        public int SocketCount { get { int n; Check(Native.chaintube_rig_socket_count(Handle, out n)); return n; } }
        public int FindSocket(string id) { int s; Check(Native.chaintube_rig_find_socket(Handle, Native.Utf8(id), out s)); return s; }
        /// <summary>Socket `socket` now: world position and axis, capture, the end it holds.</summary>
        public SocketInfo Socket(int socket) { SocketInfo info; Check(Native.chaintube_rig_socket_info(Handle, socket, out info)); return info; }

        /// <summary>Plugs end `end` (0: first point's, 1: last point's) into socket `socket`; the end
        /// eases in over the next Updates. Returns the new attachment's index. Throws for a tag
        /// that does not fit, an occupied socket, an end that is not free.</summary>
        public int Plug(int hose, int end, int socket)
        {
            int attachment;
            Check(Native.chaintube_rig_plug(Handle, hose, end, socket, out attachment));
            return attachment;
        }

        /// <summary>Unplugs end `end`: returns the socket it left (-1: an export attachment).</summary>
        public int Unplug(int hose, int end) { int s; Check(Native.chaintube_rig_unplug(Handle, hose, end, out s)); return s; }

        /// <summary>Pays out (length &gt; 0, metres) or reels in (length &lt; 0) hose at end `end`
        /// (0: first point's, 1: last point's), whose attachment is the reel's outlet; with clip
        /// &gt;= 0 through that clip, the drum towards `end`. The rest length stays within
        /// [minLength, maxLength]. A frame's call: speed * Time.deltaTime. Since ABI 1.3.</summary>
        public ReelResult Reel(int hose, int end, double length, double minLength, double maxLength, int clip = -1)
        {
            ReelResult result;
            Check(Native.chaintube_rig_reel(Handle, hose, end, clip, length, minLength, maxLength, out result));
            return result;
        }
        /// <summary>The hose's axis points now, world metres (3 doubles a point): the points Grab
        /// and Cut name (after a Reel no longer the joints' positions). Since ABI 1.3.</summary>
        public double[] AxisPoints(int hose)
        {
            var points = new double[3 * Info(hose).pointCount];
            Check(Native.chaintube_rig_axis_points(Handle, hose, points, points.Length));
            return points;
        }
        public int Update() { int n; Check(Native.chaintube_rig_update(Handle, out n)); return n; }
        /// <summary>Update for a frame of `seconds` in (0, 0.1] (Unity: Time.deltaTime, clamped to
        /// 0.1): gravity advances by that time, the same at any frame rate. Since ABI 1.4.</summary>
        public int Update(double seconds)
        {
            int n;
            Check(Native.chaintube_rig_update_seconds(Handle, seconds, out n));
            return n;
        }
        public HoseResult Result(int hose) { HoseResult r; Check(Native.chaintube_rig_hose_result(Handle, hose, out r)); return r; }

        /// <summary>local: 10 floats a joint (TRS), world: 7 (translation, rotation); either may be null.</summary>
        public void JointPoses(int hose, float[] local, float[] world)
        {
            Check(Native.chaintube_rig_joint_poses(Handle, hose, local, local == null ? 0 : local.Length,
                world, world == null ? 0 : world.Length));
        }

        /// <summary>JointPoses in double precision.</summary>
        public void JointPosesF64(int hose, double[] local, double[] world)
        {
            Check(Native.chaintube_rig_joint_poses_f64(Handle, hose, local, local == null ? 0 : local.Length,
                world, world == null ? 0 : world.Length));
        }

        /// <summary>3 floats a vertex each, world metres and unit normals; either may be null.</summary>
        public void Surface(int hose, float[] positions, float[] normals)
        {
            Check(Native.chaintube_rig_surface(Handle, hose, positions, positions == null ? 0 : positions.Length,
                normals, normals == null ? 0 : normals.Length));
        }

        /// <summary>Bounds the Newton steps a hose takes in each node move, grab and Update
        /// (16 from load, the real-time budget; 0 lifts the bound). What a frame cannot finish goes
        /// on in the next Updates (Pending).</summary>
        public void SetBudget(int newtonSteps) { Check(Native.chaintube_rig_set_budget(Handle, newtonSteps)); }

        /// <summary>Whether the hose's last update ran out of the budget and goes on in the next
        /// Update; remaining: how far it still is from its target (metres, 0 when not pending).</summary>
        public bool Pending(int hose, out double remaining)
        {
            int pending;
            Check(Native.chaintube_rig_hose_pending(Handle, hose, out pending, out remaining));
            return pending != 0;
        }

        public void Dispose()
        {
            if (Handle == IntPtr.Zero) return;
            Native.chaintube_rig_destroy(Handle);
            Handle = IntPtr.Zero;
        }
    }
}
