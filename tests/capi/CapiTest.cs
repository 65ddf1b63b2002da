// The C ABI from C#, through [DllImport] as a Unity script calls it (exporters/bindings/csharp):
//
//   mono CapiTest.exe replay <export.glb> <reference.txt>
//       replays the inputs of capi_reference's file (the C++ runtime's figures) on the rig
//       loaded from the file and from its bytes, and compares hose properties, frame results,
//       joint poses (1e-9 m, float poses equal to the doubles rounded) and surface sums
//   mono CapiTest.exe errors <test-rig.glb>
//       null handle, short buffer, index out of range, NaN target, point not grabbable, wrong
//       ABI major, unreadable file, malformed GLB bytes: each refused with its status and a
//       message, nothing changed
//   mono CapiTest.exe clip <motion-rig.glb>
//       the checks of capi_clip_test.c through the Rig wrapper: the carriage slides out to
//       +50 mm, back to -50 mm and home, 5 mm a frame; after every update the cable
//       carriage-cable is OK, passes through every clip's centre along its axis (1e-9 m), keeps
//       every segment in its band and its rest lengths, and has slid through the carriage's
//       clip at least 40 mm each way; the clip functions' refusals
//
// Exit 0: all agree; 1: a failure (each printed); 77: the export is absent (skipped).
using System;
using System.Collections.Generic;
using System.Globalization;
using System.IO;
using System.Linq;
using ChainTube;

static class CapiTest
{
    const double Tolerance = 1e-9;
    // The axial stiffness (EA, N per unit strain) capi_reference writes the pulls' forces for.
    const double PullStiffness = 1e4;
    static int failures;
    static long compared;
    static double largestDifference;

    static void Fail(string where, string what)
    {
        Console.Error.WriteLine("FAIL " + where + ": " + what);
        ++failures;
    }

    static void Ok(Status status, string where, string call)
    {
        if (status != Status.Ok) Fail(where, call + " returned " + status + ": " + Native.LastError());
    }

    static void Near(double actual, double expected, string where, string what)
    {
        double difference = Math.Abs(actual - expected);
        ++compared;
        largestDifference = Math.Max(largestDifference, difference);
        if (!(difference <= Tolerance))
            Fail(where, what + ": C ABI " + actual.ToString("R") + ", C++ runtime " + expected.ToString("R"));
    }

    static void Same(long actual, long expected, string where, string what)
    {
        ++compared;
        if (actual != expected) Fail(where, what + ": C ABI " + actual + ", C++ runtime " + expected);
    }

    static void SameFloat(float actual, float expected, string where, string what)
    {
        ++compared;
        if (actual != expected)
            Fail(where, what + ": " + actual.ToString("R") + ", expected " + expected.ToString("R") + " (the same float)");
    }

    static double[] Numbers(string[] words, int from, int count)
    {
        var values = new double[count];
        for (int k = 0; k < count; ++k)
            values[k] = double.Parse(words[from + k], NumberStyles.Float, CultureInfo.InvariantCulture);
        return values;
    }

    static void CompareResult(HoseResult r, double[] e, int at, string where)
    {
        Same((int)r.status, (long)e[at], where, "status");
        Same(r.blocked, (long)e[at + 1], where, "blocked");
        Same(r.movedPoints, (long)e[at + 2], where, "moved points");
        Same(r.contacts, (long)e[at + 3], where, "contacts");
        Near(r.lengthViolation, e[at + 4], where, "length violation");
        Near(r.angleViolation, e[at + 5], where, "angle violation");
        Near(r.grabError, e[at + 6], where, "grab error");
        Near(r.penetration, e[at + 7], where, "penetration");
    }

    static void Replay(IntPtr rig, string reference, string run)
    {
        var lines = File.ReadAllLines(reference);
        var grabResult = new HoseResult();
        var reelResult = new ReelResult();
        // Poses and surface per hose, fetched once after each change.
        var poses = new Dictionary<int, Tuple<double[], double[], float[], float[]>>();
        var surfaces = new Dictionary<int, Tuple<float[], float[]>>();
        for (int n = 0; n < lines.Length; ++n) {
            string where = run + ", reference line " + (n + 1);
            string[] words = lines[n].Split(' ');
            switch (words[0]) {
            case "rig": {
                var v = Numbers(words, 1, 2);
                int hoses, nodes;
                Ok(Native.chaintube_rig_hose_count(rig, out hoses), where, "hose_count");
                Ok(Native.chaintube_rig_node_count(rig, out nodes), where, "node_count");
                Same(hoses, (long)v[0], where, "hose count");
                Same(nodes, (long)v[1], where, "node count");
                break;
            }
            case "hose": {
                var v = Numbers(words, 1, 9);
                string id = string.Join(" ", words.Skip(10));
                HoseInfo info;
                int found;
                Ok(Native.chaintube_rig_hose_info(rig, (int)v[0], out info), where, "hose_info");
                Same(info.pointCount, (long)v[1], where, "point count");
                Same(info.jointCount, (long)v[2], where, "joint count");
                Same(info.grabbableCount, (long)v[3], where, "grabbable count");
                Same(info.vertexCount, (long)v[4], where, "vertex count");
                Same(info.indexCount, (long)v[5], where, "index count");
                Same(info.isStatic, (long)v[6], where, "static");
                Near(info.restLength, v[7], where, "rest length");
                Near(info.outerRadius, v[8], where, "outer radius");
                if (Native.String(info.id) != id) Fail(where, "id " + Native.String(info.id) + ", expected " + id);
                Ok(Native.chaintube_rig_find_hose(rig, Native.Utf8(id), out found), where, "find_hose");
                Same(found, (long)v[0], where, "find_hose(id)");
                break;
            }
            case "node-name": {
                int node = int.Parse(words[1], CultureInfo.InvariantCulture), found;
                string name = string.Join(" ", words.Skip(2));
                Ok(Native.chaintube_rig_find_node(rig, Native.Utf8(name), out found), where, "find_node");
                Same(found, node, where, "find_node(name)");
                break;
            }
            case "move": {
                var v = Numbers(words, 1, 11);
                poses.Clear();
                surfaces.Clear();
                Ok(Native.chaintube_rig_set_node_transform(rig, (int)v[0], v.Skip(1).ToArray()), where,
                   "set_node_transform");
                break;
            }
            case "grab": {
                var v = Numbers(words, 1, 5);
                poses.Clear();
                surfaces.Clear();
                Ok(Native.chaintube_rig_grab(rig, (int)v[0], (int)v[1], v.Skip(2).ToArray(), out grabResult),
                   where, "grab");
                break;
            }
            case "grab-result":
                CompareResult(grabResult, Numbers(words, 1, 8), 0, where);
                break;
            case "reel": {
                var v = Numbers(words, 1, 6);
                poses.Clear();
                surfaces.Clear();
                Ok(Native.chaintube_rig_reel(rig, (int)v[0], (int)v[1], (int)v[2], v[3], v[4], v[5], out reelResult),
                   where, "reel");
                break;
            }
            case "reel-result": {
                var v = Numbers(words, 1, 7);
                Near(reelResult.paid, v[0], where, "reel paid");
                Near(reelResult.restLength, v[1], where, "reel rest length");
                Near(reelResult.largestMove, v[2], where, "reel largest move");
                Same(reelResult.clamped, (long)v[3], where, "reel clamped");
                Same(reelResult.segmentsAdded, (long)v[4], where, "reel added");
                Same(reelResult.segmentsRemoved, (long)v[5], where, "reel removed");
                Same(reelResult.pointCount, (long)v[6], where, "reel points");
                break;
            }
            case "release":
                poses.Clear();
                surfaces.Clear();
                Ok(Native.chaintube_rig_release(rig, int.Parse(words[1], CultureInfo.InvariantCulture)),
                   where, "release");
                break;
            case "update": {
                int recomputed;
                poses.Clear();
                surfaces.Clear();
                Ok(Native.chaintube_rig_update(rig, out recomputed), where, "update");
                break;
            }
            case "result": {
                var v = Numbers(words, 1, 9);
                HoseResult result;
                Ok(Native.chaintube_rig_hose_result(rig, (int)v[0], out result), where, "hose_result");
                CompareResult(result, v, 1, where);
                break;
            }
            case "pose": {
                var v = Numbers(words, 1, 20);
                int hose = (int)v[0], joint = (int)v[1];
                if (!poses.ContainsKey(hose)) {
                    HoseInfo info;
                    Ok(Native.chaintube_rig_hose_info(rig, hose, out info), where, "hose_info");
                    var entry = Tuple.Create(new double[10 * info.jointCount], new double[7 * info.jointCount],
                                             new float[10 * info.jointCount], new float[7 * info.jointCount]);
                    Ok(Native.chaintube_rig_joint_poses_f64(rig, hose, entry.Item1, entry.Item1.Length,
                                                            entry.Item2, entry.Item2.Length), where, "joint_poses_f64");
                    Ok(Native.chaintube_rig_joint_poses(rig, hose, entry.Item3, entry.Item3.Length,
                                                        entry.Item4, entry.Item4.Length), where, "joint_poses");
                    poses[hose] = entry;
                }
                var p = poses[hose];
                for (int k = 0; k < 10; ++k) {
                    Near(p.Item1[10 * joint + k], v[3 + k], where, "local pose [" + k + "]");
                    SameFloat(p.Item3[10 * joint + k], (float)p.Item1[10 * joint + k], where,
                              "float local pose vs the double one rounded");
                }
                for (int k = 0; k < 7; ++k) {
                    Near(p.Item2[7 * joint + k], v[13 + k], where, "world pose [" + k + "]");
                    SameFloat(p.Item4[7 * joint + k], (float)p.Item2[7 * joint + k], where,
                              "float world pose vs the double one rounded");
                }
                break;
            }
            case "surface": {
                var v = Numbers(words, 1, 6);
                int hose = (int)v[0];
                HoseInfo info;
                Ok(Native.chaintube_rig_hose_info(rig, hose, out info), where, "hose_info");
                var positions = new float[3 * info.vertexCount];
                var normals = new float[3 * info.vertexCount];
                var indices = new uint[info.indexCount];
                var uvs = new float[2 * info.vertexCount];
                Ok(Native.chaintube_rig_surface(rig, hose, positions, positions.Length, normals, normals.Length),
                   where, "surface");
                Ok(Native.chaintube_rig_surface_topology(rig, hose, indices, indices.Length, uvs, uvs.Length),
                   where, "surface_topology");
                surfaces[hose] = Tuple.Create(positions, normals);
                double positionSum = 0, normalSum = 0, indexSum = 0, uvSum = 0;
                for (int k = 0; k < positions.Length; ++k) {
                    positionSum += positions[k];
                    normalSum += normals[k];
                }
                foreach (uint index in indices) indexSum += index;
                foreach (float uv in uvs) uvSum += uv;
                Same(info.vertexCount, (long)v[1], where, "vertex count");
                Near(positionSum, v[2], where, "sum of surface positions");
                Near(normalSum, v[3], where, "sum of surface normals");
                Near(indexSum, v[4], where, "sum of surface indices");
                Near(uvSum, v[5], where, "sum of surface uvs");
                break;
            }
            case "vertex": {
                var v = Numbers(words, 1, 8);
                var s = surfaces[(int)v[0]];
                int vertex = (int)v[1];
                for (int k = 0; k < 3; ++k) {
                    SameFloat(s.Item1[3 * vertex + k], (float)v[2 + k], where, "surface position");
                    SameFloat(s.Item2[3 * vertex + k], (float)v[5 + k], where, "surface normal");
                }
                break;
            }
            case "attachments": {
                var v = Numbers(words, 1, 2);
                int count;
                Ok(Native.chaintube_rig_attachment_count(rig, (int)v[0], out count), where, "attachment_count");
                Same(count, (long)v[1], where, "attachment count");
                break;
            }
            case "pull": {
                var v = Numbers(words, 1, 13);
                AttachmentPull pull;
                Ok(Native.chaintube_rig_attachment_pull(rig, (int)v[0], (int)v[1], PullStiffness, out pull), where,
                   "attachment_pull");
                Same(pull.node, (long)v[2], where, "attachment node");
                Same(pull.firstPoint, (long)v[3], where, "attachment first point");
                Same(pull.lastPoint, (long)v[4], where, "attachment last point");
                Near(pull.tautness, v[5], where, "tautness");
                Near(pull.strain, v[6], where, "strain");
                Near(pull.directionX, v[7], where, "pull direction x");
                Near(pull.directionY, v[8], where, "pull direction y");
                Near(pull.directionZ, v[9], where, "pull direction z");
                Near(pull.forceX / PullStiffness, v[10] / PullStiffness, where, "pull force x / EA");
                Near(pull.forceY / PullStiffness, v[11] / PullStiffness, where, "pull force y / EA");
                Near(pull.forceZ / PullStiffness, v[12] / PullStiffness, where, "pull force z / EA");
                break;
            }
            case "socket": {
                var v = Numbers(words, 1, 11);
                string id = string.Join(" ", words.Skip(12));
                SocketInfo info;
                int found;
                Ok(Native.chaintube_rig_socket_info(rig, (int)v[0], out info), where, "socket_info");
                Same(info.node, (long)v[1], where, "socket node");
                Same(info.occupantHose, (long)v[2], where, "socket occupant hose");
                Same(info.occupantEnd, (long)v[3], where, "socket occupant end");
                Same(info.occupantAttachment, (long)v[4], where, "socket occupant attachment");
                Near(info.positionX, v[5], where, "socket position x");
                Near(info.positionY, v[6], where, "socket position y");
                Near(info.positionZ, v[7], where, "socket position z");
                Near(info.axisX, v[8], where, "socket axis x");
                Near(info.axisY, v[9], where, "socket axis y");
                Near(info.axisZ, v[10], where, "socket axis z");
                if (Native.String(info.id) != id) Fail(where, "socket id " + Native.String(info.id) + ", expected " + id);
                Ok(Native.chaintube_rig_find_socket(rig, Native.Utf8(id), out found), where, "find_socket");
                Same(found, (long)v[0], where, "find_socket(id)");
                break;
            }
            case "unplug": {
                var v = Numbers(words, 1, 3);
                int left;
                poses.Clear();
                surfaces.Clear();
                Ok(Native.chaintube_rig_unplug(rig, (int)v[0], (int)v[1], out left), where, "unplug");
                Same(left, (long)v[2], where, "the socket unplugged from");
                break;
            }
            case "plug": {
                var v = Numbers(words, 1, 4);
                int attachment;
                poses.Clear();
                surfaces.Clear();
                Ok(Native.chaintube_rig_plug(rig, (int)v[0], (int)v[1], (int)v[2], out attachment), where, "plug");
                Same(attachment, (long)v[3], where, "the plug's attachment");
                break;
            }
            case "release-snap": {
                var v = Numbers(words, 1, 2);
                int socket;
                poses.Clear();
                surfaces.Clear();
                Ok(Native.chaintube_rig_release_snap(rig, (int)v[0], out socket), where, "release_snap");
                Same(socket, (long)v[1], where, "the socket snapped into");
                break;
            }
            default:
                Fail(where, "unknown reference line");
                break;
            }
        }
    }

    static int RunReplay(string export, string reference)
    {
        if (!File.Exists(export)) {
            Console.WriteLine("skipped: " + export + " is absent (the engine samples need ../shared/scenes)");
            return 77;
        }
        IntPtr rig;
        Ok(Native.chaintube_rig_load_file(Native.AbiVersion, Native.Utf8(export), out rig), "file", "load_file");
        if (rig != IntPtr.Zero) {
            Replay(rig, reference, "loaded from the file");
            Ok(Native.chaintube_rig_destroy(rig), "file", "destroy");
        }
        // As a Unity script loads a .glb shipped as a TextAsset: from its bytes.
        using (Rig fromBytes = Rig.LoadMemory(Path.GetFileName(export), File.ReadAllBytes(export)))
            Replay(fromBytes.Handle, reference, "loaded from memory");
        Console.WriteLine("CapiTest replay: " + export + ", loaded from the file and from memory: " + compared +
                          " figures compared with the C++ runtime, largest difference " +
                          largestDifference.ToString("G3", CultureInfo.InvariantCulture) + " (tolerance " +
                          Tolerance.ToString(CultureInfo.InvariantCulture) + "), " + failures + " failures");
        return failures == 0 && compared > 0 ? 0 : 1;
    }

    static void Refused(Status status, Status expected, string what, params string[] words)
    {
        string message = Native.LastError();
        ++compared;
        if (status != expected) {
            Fail(what, "returned " + status + ", expected " + expected + " (" + message + ")");
            return;
        }
        foreach (string word in words)
            if (!message.Contains(word)) Fail(what, "the message does not name \"" + word + "\": " + message);
    }

    static double[] WorldPoses(IntPtr rig, int hose, int joints)
    {
        var world = new double[7 * joints];
        Ok(Native.chaintube_rig_joint_poses_f64(rig, hose, null, 0, world, world.Length), "snapshot", "poses");
        return world;
    }

    static int RunErrors(string export)
    {
        IntPtr rig;
        uint nextMajor = (Native.AbiVersion >> 16) + 1 << 16;
        Same(Native.chaintube_runtime_abi_version(), Native.AbiVersion, "abi", "the library's ABI version");
        Refused(Native.chaintube_rig_load_file(nextMajor, Native.Utf8(export), out rig), Status.AbiMismatch,
                "wrong ABI major", "ABI 2.0", "ABI 1.4");
        // A caller built against an older minor version (1.1: before the attachment pulls) still loads.
        Ok(Native.chaintube_rig_load_file((1u << 16) | 1u, Native.Utf8(export), out rig), "abi 1.1", "load_file");
        Ok(Native.chaintube_rig_destroy(rig), "abi 1.1", "destroy");
        Refused(Native.chaintube_rig_load_file(Native.AbiVersion, Native.Utf8("/nonexistent/rig.glb"), out rig),
                Status.UnreadableFile, "unreadable file", "/nonexistent/rig.glb", "cannot be read");
        byte[] glb = File.ReadAllBytes(export);
        byte[] broken = (byte[])glb.Clone();
        broken[4] = 3; // GLB container version 3
        Refused(Native.chaintube_rig_load_memory(Native.AbiVersion, Native.Utf8("broken.glb"), broken,
                                                 (UIntPtr)broken.Length, null, 0, null, UIntPtr.Zero, out rig),
                Status.Malformed, "malformed GLB", "broken.glb", "version 3, expected 2");
        Refused(Native.chaintube_rig_load_memory(Native.AbiVersion, Native.Utf8("short.glb"), glb, (UIntPtr)16,
                                                 null, 0, null, UIntPtr.Zero, out rig),
                Status.Malformed, "truncated GLB", "short.glb", "truncated");
        try {
            Rig.LoadFile("/nonexistent/rig.glb");
            Fail("wrapper", "loaded a missing file");
        } catch (ChainTubeException error) {
            Same((int)error.Status, (int)Status.UnreadableFile, "wrapper", "exception status");
        }

        int count;
        HoseResult result;
        Refused(Native.chaintube_rig_hose_count(IntPtr.Zero, out count), Status.InvalidArgument, "null handle",
                "chaintube_rig_hose_count", "rig is NULL");
        Refused(Native.chaintube_rig_update(IntPtr.Zero, out count), Status.InvalidArgument, "null handle",
                "rig is NULL");
        Refused(Native.chaintube_rig_grab(IntPtr.Zero, 0, 1, new double[3], out result), Status.InvalidArgument,
                "null handle", "rig is NULL");

        using (Rig owned = Rig.LoadMemory("test-rig.glb", glb)) {
            IntPtr r = owned.Handle;
            int hose = owned.FindHose("left-feed");
            HoseInfo info = owned.Info(hose);
            int[] grabbable = owned.GrabbablePoints(hose);
            int point = grabbable[grabbable.Length / 2];
            double[] before = WorldPoses(r, hose, info.jointCount);

            Refused(Native.chaintube_rig_hose_info(r, owned.HoseCount, out info), Status.OutOfRange,
                    "hose out of range", "hose 2 is out of range");
            Refused(Native.chaintube_rig_grab(r, hose, info.pointCount, new double[3], out result),
                    Status.OutOfRange, "point out of range", "point", "left-feed");
            Refused(Native.chaintube_rig_grab(r, hose, 0, new double[3], out result), Status.NotGrabbable,
                    "fixed point", "not grabbable");
            Refused(Native.chaintube_rig_grab(r, hose, point, new[] { 0.1, double.NaN, 0.0 }, out result),
                    Status.InvalidArgument, "NaN target", "target[1] is NaN");
            var trs = new double[10];
            Ok(Native.chaintube_rig_node_transform(r, 0, trs), "node", "node_transform");
            trs[9] = double.PositiveInfinity;
            Refused(Native.chaintube_rig_set_node_transform(r, 0, trs), Status.InvalidArgument, "Inf scale",
                    "trs[9] (scale z) is +Inf");
            var shortLocal = new float[10 * info.jointCount - 1];
            Refused(Native.chaintube_rig_joint_poses(r, hose, shortLocal, shortLocal.Length, null, 0),
                    Status.BufferTooSmall, "short buffer", "local has room for " + shortLocal.Length);
            var shortSurface = new float[3 * info.vertexCount - 3];
            Refused(Native.chaintube_rig_surface(r, hose, shortSurface, shortSurface.Length, null, 0),
                    Status.BufferTooSmall, "short buffer", "positions has room for");
            AttachmentPull unusedPull;
            Refused(Native.chaintube_rig_attachment_pull(r, hose, 2, 1e4, out unusedPull), Status.OutOfRange,
                    "attachment out of range", "attachment 2 is out of range", "left-feed");
            Refused(Native.chaintube_rig_attachment_pull(r, hose, 0, double.NaN, out unusedPull),
                    Status.InvalidArgument, "NaN axial stiffness", "axial_stiffness", "finite EA >= 0");
            Refused(Native.chaintube_rig_attachment_pull(r, hose, 0, -5.0, out unusedPull), Status.InvalidArgument,
                    "negative axial stiffness", "axial_stiffness");
            Same(shortLocal.Count(x => x != 0) + shortSurface.Count(x => x != 0), 0, "short buffer",
                 "floats written by refused calls");
            owned.Update();
            double[] after = WorldPoses(r, hose, info.jointCount);
            Same(before.SequenceEqual(after) ? 1 : 0, 1, "refused calls", "poses unchanged after an update");

            // With good input the same calls work: the grabbed joint goes to the target.
            double[] target = { before[7 * point], before[7 * point + 1] + 0.01, before[7 * point + 2] }; // within reach
            HoseResult grab = owned.Grab(hose, point, target[0], target[1], target[2]);
            Same((int)grab.status, (int)HoseStatus.Ok, "grab", "status");
            owned.Update();
            double[] moved = WorldPoses(r, hose, info.jointCount);
            for (int k = 0; k < 3; ++k) Near(moved[7 * point + k], target[k], "grab", "grabbed joint at the target");
            Same(owned.Result(hose).movedPoints > 0 ? 1 : 0, 1, "grab", "frame result counts moved points");
            // Tension: right-return drawn taut by its valve moved 10 cm away, slack once it goes
            // back (the valve's parent has no rotation or scale: see capi_errors_test.c).
            int right = owned.FindHose("right-return"), valve = owned.FindNode("valve");
            Same(owned.AttachmentCount(right), 2, "pull", "attachments of right-return");
            double[] ends = WorldPoses(r, right, owned.Info(right).jointCount);
            int last = 7 * (owned.Info(right).jointCount - 1);
            var away = new[] { ends[last] - ends[0], ends[last + 1] - ends[1], ends[last + 2] - ends[2] };
            double length = Math.Sqrt(away.Sum(x => x * x));
            double[] home = owned.NodeTransform(valve), away10 = (double[])home.Clone();
            for (int frame = 0; frame < 5; ++frame) {
                for (int k = 0; k < 3; ++k) away10[k] += 0.02 * away[k] / length;
                owned.SetNodeTransform(valve, away10);
                owned.Update();
            }
            for (int a = 0; a < 2; ++a) {
                AttachmentPull pull = owned.Pull(right, a, 1e4);
                Expect(pull.tautness > 0.9 && pull.strain > 0.0, "drawn taut",
                       "attachment " + a + ": tautness " + pull.tautness + ", strain " + pull.strain);
            }
            owned.SetNodeTransform(valve, home);
            owned.Update();
            for (int a = 0; a < 2; ++a) {
                AttachmentPull pull = owned.Pull(right, a, 1e4);
                Expect(pull.tautness == 0.0 && pull.forceX == 0.0 && pull.forceY == 0.0 && pull.forceZ == 0.0,
                       "released", "attachment " + a + ": tautness " + pull.tautness);
            }
            // Sockets through Rig: a plug that does not fit is refused; left-feed's valve end
            // unplugged and plugged into plate-port eases in and sits on it.
            int feed = owned.FindHose("left-feed"), plate = owned.FindSocket("plate-port");
            int outlet = owned.FindSocket("valve-outlet");
            Same(owned.SocketCount, 2, "sockets", "socket count");
            Action<Action, string> refusedWith = (call, words) => {
                try {
                    call();
                    Fail("sockets", "not refused: " + words);
                } catch (ChainTubeException error) {
                    Expect(error.Status == Status.InvalidArgument && error.Message.Contains(words), "sockets",
                           error.Status + ": " + error.Message);
                }
            };
            refusedWith(() => owned.Plug(feed, 0, outlet), "has no plug");
            refusedWith(() => owned.Plug(feed, 1, outlet), "already attached");
            refusedWith(() => owned.Unplug(right, 2), "end 2");
            Same(owned.Unplug(feed, 1), -1, "sockets", "unplugged from no socket (the export's attachment)");
            int plugged = owned.Plug(feed, 1, plate);
            Same(plugged, 2, "sockets", "the plug's attachment");
            SocketInfo held = owned.Socket(plate);
            Same(held.occupantHose, feed, "sockets", "plate-port holds left-feed");
            Same(held.occupantEnd, 1, "sockets", "plate-port holds its end 1");
            refusedWith(() => owned.Plug(right, 1, plate), "(\"right-return\") has no plug");
            for (int frame = 0; frame < 5; ++frame) {
                owned.Update();
                Same((int)owned.Result(feed).status, (int)HoseStatus.Ok, "sockets", "easing frame " + frame);
            }
            double[] seated = WorldPoses(r, feed, owned.Info(feed).jointCount);
            int tip = 7 * (owned.Info(feed).jointCount - 1);
            Near(seated[tip], held.positionX, "sockets", "end on plate-port x");
            Near(seated[tip + 1], held.positionY, "sockets", "end on plate-port y");
            Near(seated[tip + 2], held.positionZ, "sockets", "end on plate-port z");
            Same(owned.Unplug(feed, 1), plate, "sockets", "unplugged from plate-port");
            Same(owned.Socket(plate).occupantHose, -1, "sockets", "plate-port free again");
        }
        Console.WriteLine("CapiTest errors: " + compared + " checks, " + failures + " failures");
        return failures == 0 ? 0 : 1;
    }

    static void Expect(bool condition, string where, string what)
    {
        ++compared;
        if (!condition) Fail(where, what);
    }

    static double Distance(double[] a, int i, double[] b, int j)
    {
        double dx = a[i] - b[j], dy = a[i + 1] - b[j + 1], dz = a[i + 2] - b[j + 2];
        return Math.Sqrt(dx * dx + dy * dy + dz * dz);
    }

    // The cable after an update (see capi_clip_test.c); returns the carriage clip.
    static ClipInfo CheckCable(Rig rig, int hose, int carriageClip, double[] rest, double band,
                               double restLength, string when)
    {
        const double tolerance = 1e-9;
        HoseResult result = rig.Result(hose);
        Expect(result.status == HoseStatus.Ok, when, "status " + result.status);
        Expect(result.lengthViolation <= tolerance && result.angleViolation <= tolerance, when,
               "violations " + result.lengthViolation + " (length), " + result.angleViolation + " rad");
        HoseInfo info = rig.Info(hose);
        Expect(info.restLength == restLength, when, "rest length " + info.restLength.ToString("R"));
        double bandNow;
        double[] restNow = rig.RestLengths(hose, out bandNow);
        Expect(bandNow == band && restNow.SequenceEqual(rest), when, "rest lengths or band changed");
        var world = new double[7 * info.jointCount];
        rig.JointPosesF64(hose, null, world);
        var prefix = new double[rest.Length + 1];
        for (int s = 0; s < rest.Length; ++s) {
            prefix[s + 1] = prefix[s] + rest[s];
            double stretch = Distance(world, 7 * (s + 1), world, 7 * s) / rest[s] - 1.0;
            Expect(Math.Abs(stretch) <= band + tolerance, when,
                   "segment " + s + " stretched " + (100 * stretch).ToString("G3") + " % (band " + 100 * band + " %)");
        }
        var carriage = new ClipInfo();
        for (int k = 0; k < rig.ClipCount(hose); ++k) {
            ClipInfo clip = rig.Clip(hose, k);
            int j = clip.segment;
            if (!(j >= 0 && j + 1 <= rest.Length)) {
                Fail(when, "clip " + k + " segment " + j);
                continue;
            }
            double[] centre = { clip.centreX, clip.centreY, clip.centreZ };
            double[] axis = { clip.axisX, clip.axisY, clip.axisZ };
            Expect(Math.Abs(Math.Sqrt(axis.Sum(x => x * x)) - 1.0) <= tolerance, when, "clip " + k + " axis not unit");
            Expect(clip.gap <= tolerance, when, "clip " + k + " gap " + clip.gap);
            Expect(clip.slideMin <= clip.slide && clip.slide <= clip.slideMax, when, "clip " + k + " slide beyond its stops");
            Expect(prefix[j] <= clip.slide + tolerance && clip.slide <= prefix[j + 1] + tolerance, when,
                   "clip " + k + " slide " + clip.slide.ToString("R") + " not on its segment " + j);
            // Through the centre along the axis: each held point at its rest distance from it.
            double along = clip.slide - prefix[j];
            for (int a = 0; a < 3; ++a) {
                double first = centre[a] - along * axis[a], second = centre[a] + (rest[j] - along) * axis[a];
                Expect(Math.Abs(world[7 * j + a] - first) <= tolerance &&
                       Math.Abs(world[7 * (j + 1) + a] - second) <= tolerance, when,
                       "clip " + k + ": point " + j + " or " + (j + 1) + " off the clip's axis");
            }
            // The arc from point 0 to the centre is the slide within the band.
            double arc = along;
            for (int s = 0; s < j; ++s) arc += Distance(world, 7 * (s + 1), world, 7 * s);
            Expect(Math.Abs(arc / clip.slide - 1.0) <= band + tolerance, when,
                   "clip " + k + ": arc " + arc.ToString("R") + " m for a slide of " + clip.slide.ToString("R") + " m");
            if (k == carriageClip) carriage = clip;
        }
        return carriage;
    }

    static int RunClip(string export)
    {
        using (Rig rig = Rig.LoadMemory(Path.GetFileName(export), File.ReadAllBytes(export))) {
            int hose = rig.FindHose("carriage-cable"), other = rig.FindHose("carriage-feed");
            int carriage = rig.FindNode("carriage"), plate = rig.FindNode("base_plate");
            HoseInfo info = rig.Info(hose);
            double band;
            double[] rest = rig.RestLengths(hose, out band);
            Same(rig.ClipCount(hose), 2, "as loaded", "clips of carriage-cable");
            Same(rig.ClipCount(other), 0, "as loaded", "clips of carriage-feed");
            Same(rest.Length, info.pointCount - 1, "as loaded", "rest lengths");
            Expect(band == 0.02, "as loaded", "band " + band + ", expected the cable bundle's 0.02");
            Expect(Math.Abs(rest.Sum() - info.restLength) <= 1e-9, "as loaded", "rest lengths sum to rest_length");
            ClipInfo first = rig.Clip(hose, 0), second = rig.Clip(hose, 1);
            Same(first.node, carriage, "as loaded", "clip 0's node");
            Same(second.node, plate, "as loaded", "clip 1's node");
            Same(first.turning, 0, "as loaded", "clip 0 sliding");
            ClipInfo home = CheckCable(rig, hose, 0, rest, band, info.restLength, "as loaded");
            Near(home.slide, 0.3, "as loaded", "the carriage clip's exported place");
            double[] trs = rig.NodeTransform(carriage);
            double x0 = trs[0], slideMin = home.slide, slideMax = home.slide;
            int frames = 0;
            // Out to +50 mm, back to -50 mm, home: 5 mm a frame.
            for (int step = 1; step <= 40; ++step) {
                int millimetres = step <= 10 ? 5 * step : step <= 30 ? 100 - 5 * step : 5 * step - 200;
                string when = "frame " + step + ", carriage at " + millimetres + " mm";
                trs[0] = x0 + 0.001 * millimetres;
                rig.SetNodeTransform(carriage, trs);
                rig.Update();
                ++frames;
                ClipInfo clip = CheckCable(rig, hose, 0, rest, band, info.restLength, when);
                // The clip goes with the carriage (the sample's parents are identity transforms).
                Near(clip.centreX, home.centreX + 0.001 * millimetres, when, "the clip's centre x");
                Near(clip.centreY, home.centreY, when, "the clip's centre y");
                Near(clip.centreZ, home.centreZ, when, "the clip's centre z");
                slideMin = Math.Min(slideMin, clip.slide);
                slideMax = Math.Max(slideMax, clip.slide);
                if (millimetres == 50)
                    Expect(clip.slide - home.slide >= 0.04, when, "slid " + (clip.slide - home.slide) + " m, expected 0.04+");
                if (millimetres == -50)
                    Expect(home.slide - clip.slide >= 0.04, when, "slid back " + (home.slide - clip.slide) + " m, expected 0.04+");
            }
            Same(frames, 40, "frames", "frames run");

            ClipInfo unused;
            double bandOnly;
            Refused(Native.chaintube_rig_clip_info(rig.Handle, hose, 2, out unused), Status.OutOfRange,
                    "clip out of range", "clip 2 is out of range", "carriage-cable");
            Refused(Native.chaintube_rig_clip_info(rig.Handle, other, 0, out unused), Status.OutOfRange,
                    "a hose without clips", "has 0 clips");
            Refused(Native.chaintube_rig_rest_lengths(rig.Handle, hose, new double[3], 3, out bandOnly),
                    Status.BufferTooSmall, "short buffer", "rest_lengths has room for 3");
            try {
                rig.Clip(hose, -1);
                Fail("wrapper", "clip -1 accepted");
            } catch (ChainTubeException error) {
                Same((int)error.Status, (int)Status.OutOfRange, "wrapper", "exception status");
            }
            Console.WriteLine("CapiTest clip: " + export + ": carriage-cable through 2 clips over " + frames +
                              " frames of the carriage (+-50 mm): the carriage clip's slide " +
                              slideMin.ToString("F4", CultureInfo.InvariantCulture) + " ... " +
                              slideMax.ToString("F4", CultureInfo.InvariantCulture) + " m, " + compared +
                              " checks, " + failures + " failures");
        }
        return failures == 0 ? 0 : 1;
    }

    // The rigid part of a node's world transform (see capi_actions_test.c): unit axes (3 columns
    // of 3) and origin, composed from the nodes' local T * R * S up to the root.
    static void RigidWorld(Rig rig, int node, out double[] axes, out double[] origin)
    {
        var m = new double[16];
        for (int k = 0; k < 16; ++k) m[k] = k % 5 == 0 ? 1.0 : 0.0;
        for (int n = node; n >= 0;) {
            double[] t = rig.NodeTransform(n);
            double x = t[3], y = t[4], z = t[5], w = t[6];
            var l = new double[] {
                (1 - 2 * (y * y + z * z)) * t[7], 2 * (x * y + z * w) * t[7], 2 * (x * z - y * w) * t[7], 0,
                2 * (x * y - z * w) * t[8], (1 - 2 * (x * x + z * z)) * t[8], 2 * (y * z + x * w) * t[8], 0,
                2 * (x * z + y * w) * t[9], 2 * (y * z - x * w) * t[9], (1 - 2 * (x * x + y * y)) * t[9], 0,
                t[0], t[1], t[2], 1 };
            var product = new double[16];
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r)
                    for (int k = 0; k < 4; ++k) product[4 * c + r] += l[4 * k + r] * m[4 * c + k];
            m = product;
            NodeInfo info;
            Ok(Native.chaintube_rig_node_info(rig.Handle, n, out info), "node", "node_info");
            n = info.parent;
        }
        axes = new double[9];
        origin = new[] { m[12], m[13], m[14] };
        for (int c = 0; c < 3; ++c) {
            double length = Math.Sqrt(m[4 * c] * m[4 * c] + m[4 * c + 1] * m[4 * c + 1] + m[4 * c + 2] * m[4 * c + 2]);
            for (int r = 0; r < 3; ++r) axes[3 * c + r] = m[4 * c + r] / length;
        }
    }

    static void ExpectInBand(Rig rig, int hose, double[] rest, double band, string when)
    {
        double[] world = WorldPoses(rig.Handle, hose, rest.Length + 1);
        for (int s = 0; s < rest.Length; ++s) {
            double length = Distance(world, 7 * (s + 1), world, 7 * s);
            Expect(Math.Abs(length / rest[s] - 1.0) <= band + 1e-9, when,
                   "segment " + s + " is " + length.ToString("R") + " m, rest " + rest[s].ToString("R") + " m");
        }
    }

    // An end unplugged and plugged into another part (see capi_actions_test.c), as a Unity
    // script does it through the wrapper.
    static int RunActions(string export)
    {
        using (Rig rig = Rig.LoadMemory(Path.GetFileName(export), File.ReadAllBytes(export))) {
            int tail = rig.FindHose("valve-tail"), bracket = rig.FindNode("bracket_left");
            int n = rig.Info(tail).pointCount;
            double band;
            double[] rest = rig.RestLengths(tail, out band);
            Same(rig.AttachmentCount(tail), 1, "as loaded", "attachments of valve-tail");
            double[] world = WorldPoses(rig.Handle, tail, n);
            rig.Grab(tail, n - 1, world[7 * (n - 1)], world[7 * (n - 1) + 1], world[7 * (n - 1) + 2]);
            rig.Update();
            rig.DetachEnd(tail, 0);
            Same(rig.Pull(tail, 0, 0.0).attached, 0, "unplugged", "attached");
            Same(rig.Info(tail).grabbableCount, n, "unplugged", "grabbable points");
            double startHeight = WorldPoses(rig.Handle, tail, n)[1];
            for (int frame = 0; frame < 10; ++frame) {
                rig.Update();
                ExpectInBand(rig, tail, rest, band, "falling, frame " + frame);
                Expect(rig.Result(tail).status != HoseStatus.Infeasible, "falling, frame " + frame, "infeasible");
            }
            world = WorldPoses(rig.Handle, tail, n);
            double drop = startHeight - world[1];
            Expect(drop > 1e-3, "fallen", "the unplugged end fell " + drop + " m");

            // Refused: status and message, nothing changed.
            HoseResult unused;
            int unusedIndex;
            var identity = new double[] { 0, 0, 0, 0, 0, 0, 1 };
            Refused(Native.chaintube_rig_detach_end(rig.Handle, tail, 0, out unused), Status.InvalidArgument,
                    "detach a detached end", "already detached");
            Refused(Native.chaintube_rig_attach_end(rig.Handle, tail, 2, bracket, identity, out unusedIndex, out unused),
                    Status.InvalidArgument, "end 2", "end 2: expected 0");
            Refused(Native.chaintube_rig_attach_end(rig.Handle, tail, 0, rig.NodeCount, identity, out unusedIndex,
                                                    out unused), Status.OutOfRange, "node out of range", "is out of range");
            Refused(Native.chaintube_rig_attach_end(rig.Handle, tail, 0, bracket, new[] { 0, 0, double.NaN, 0, 0, 0, 1 },
                                                    out unusedIndex, out unused),
                    Status.InvalidArgument, "NaN pose", "pose[2] (translation z) is NaN");
            Expect(WorldPoses(rig.Handle, tail, n).SequenceEqual(world), "refused", "a refused call moved the hose");

            // Plug the end into the bracket 1 cm above where it hangs, along the bracket's +z.
            double[] axes, origin;
            RigidWorld(rig, bracket, out axes, out origin);
            var socket = new[] { world[0], world[1] + 0.01, world[2] };
            var pose = new double[] { 0, 0, 0, 0, 0, 0, 1 };
            for (int c = 0; c < 3; ++c)
                for (int r = 0; r < 3; ++r) pose[c] += axes[3 * c + r] * (socket[r] - origin[r]);
            HoseResult plugged;
            int index = rig.AttachEnd(tail, 0, bracket, pose, out plugged);
            Same(index, 1, "plugged", "attachment index");
            Same((int)plugged.status, (int)HoseStatus.Ok, "plugged", "status");
            rig.Update();
            world = WorldPoses(rig.Handle, tail, n);
            Expect(Distance(world, 0, socket, 0) < 1e-9, "plugged", "the end is " + Distance(world, 0, socket, 0) + " m from the socket");
            ExpectInBand(rig, tail, rest, band, "plugged");
            Refused(Native.chaintube_rig_attach_end(rig.Handle, tail, 0, bracket, pose, out unusedIndex, out unused),
                    Status.InvalidArgument, "plug the same end again", "already attached");

            // The bracket moves; the end goes with it.
            double[] trs = rig.NodeTransform(bracket);
            for (int frame = 0; frame < 3; ++frame) {
                trs[0] += 0.02;
                rig.SetNodeTransform(bracket, trs);
                rig.Update();
                RigidWorld(rig, bracket, out axes, out origin);
                var expected = new double[3];
                for (int r = 0; r < 3; ++r)
                    expected[r] = origin[r] + axes[r] * pose[0] + axes[3 + r] * pose[1] + axes[6 + r] * pose[2];
                world = WorldPoses(rig.Handle, tail, n);
                Expect(Distance(world, 0, expected, 0) < 1e-9, "bracket moved, frame " + frame,
                       "the end is " + Distance(world, 0, expected, 0) + " m from its place on the bracket");
                Same((int)rig.Result(tail).status, (int)HoseStatus.Ok, "bracket moved, frame " + frame, "status");
                ExpectInBand(rig, tail, rest, band, "bracket moved, frame " + frame);
            }
            // Cut bracket-loop at its middle: the new hose is the next index and poses the joints
            // beyond the cut (its first joint node -1); a cut at an end is refused.
            int loop = rig.FindHose("bracket-loop"), hoses = rig.HoseCount;
            int points = rig.Info(loop).pointCount, middle = points / 2;
            Refused(Native.chaintube_rig_cut(rig.Handle, loop, 0, out unusedIndex), Status.InvalidArgument,
                    "cut at an end", "expected an interior point");
            Same(rig.HoseCount, hoses, "refused cut", "hose count");
            int piece = rig.Cut(loop, middle);
            Same(piece, hoses, "cut", "new hose index");
            Same(rig.Info(loop).pointCount, middle + 1, "cut", "points of the hose cut");
            Same(rig.Info(piece).pointCount, points - middle, "cut", "points of the new hose");
            var pieceNodes = new int[rig.Info(piece).jointCount];
            Ok(Native.chaintube_rig_joint_nodes(rig.Handle, piece, pieceNodes, pieceNodes.Length), "cut", "joint_nodes");
            Same(pieceNodes[0], -1, "cut", "the new hose's first joint node");
            // Reel: valve-tail, let go by the hand, plugged into the bracket at end 0, pays out 5 cm
            // (rig.Reel, 0.5 m/s at 90 Hz; a clamped frame's rest is paid the next frame) and takes
            // back what it can; refusals change nothing.
            rig.Release(tail);
            double length0 = rig.Info(tail).restLength;
            int joints0 = rig.Info(tail).jointCount;
            double paidIn = 0.0;
            foreach (int direction in new[] { +1, -1 }) {
                double left = 0.05;
                for (int frame = 0; frame < 60 && left > 1e-12; ++frame) {
                    ReelResult reel = rig.Reel(tail, 0, direction * Math.Min(left, 0.5 / 90), 0.0, 10.0);
                    left -= Math.Abs(reel.paid);
                    Same(reel.pointCount, rig.Info(tail).pointCount, "reel, frame " + frame, "points");
                    rig.Update();
                    Same(rig.Info(tail).jointCount, joints0, "reel, frame " + frame, "joint count");
                    Expect(rig.AxisPoints(tail).Length == 3 * rig.Info(tail).pointCount, "reel", "axis points");
                }
                // Paid out in full; reeling in, a frame whose step would move a point more than
                // twice its length waits (lib/README.md): as far as it goes.
                if (direction > 0) Expect(left <= 1e-12, "paying out", left + " m left");
                else paidIn = 0.05 - left;
            }
            Expect(paidIn > 0.0, "reeling in", "nothing reeled in");
            Near(rig.Info(tail).restLength, length0 + 0.05 - paidIn, "reeled back", "rest length");
            length0 = rig.Info(tail).restLength;
            ReelResult unusedReel;
            Refused(Native.chaintube_rig_reel(rig.Handle, tail, 2, -1, 0.01, 0, 10, out unusedReel),
                    Status.InvalidArgument, "reel at end 2", "end 2");
            Refused(Native.chaintube_rig_reel(rig.Handle, tail, 0, -1, 0.01, 2, 1, out unusedReel),
                    Status.InvalidArgument, "reel bounds inverted", "maxLength");
            Refused(Native.chaintube_rig_reel(rig.Handle, tail, 1, -1, 0.01, 0, 10, out unusedReel),
                    Status.InvalidArgument, "reel at a free end", "expected an end fixed");
            Refused(Native.chaintube_rig_reel(rig.Handle, tail, 0, 0, 0.01, 0, 10, out unusedReel),
                    Status.OutOfRange, "reel through a clip out of range", "clip 0 is out of range");
            Near(rig.Info(tail).restLength, length0, "refused reels", "rest length");
            Console.WriteLine("CapiTest actions: " + export + ": valve-tail unplugged, fell " +
                              drop.ToString("G4", CultureInfo.InvariantCulture) + " m in 10 updates, plugged into " +
                              "bracket_left and followed it 0.06 m: " + compared + " checks, " + failures + " failures");
        }
        return failures == 0 ? 0 : 1;
    }

    // The work of a frame (see capi_budget_test.c): a valve jump beyond a small budget is pending
    // and met over the next Updates, every segment in its band; refusals.
    // The frame's time (ABI 1.4): bad times refused, the hose unchanged; Update(1/90) is Update().
    static int RunFrameRate(string export)
    {
        byte[] glb = File.ReadAllBytes(export);
        using (Rig timed = Rig.LoadMemory(Path.GetFileName(export), glb))
        using (Rig plain = Rig.LoadMemory(Path.GetFileName(export), glb)) {
            int hose = timed.FindHose("valve-tail"), valve = timed.FindNode("valve");
            int joints = timed.Info(hose).jointCount;
            double[] trs = timed.NodeTransform(valve);
            trs[0] += 0.03;
            timed.SetNodeTransform(valve, trs);
            plain.SetNodeTransform(valve, trs);
            double[] before = WorldPoses(timed.Handle, hose, joints);
            int recomputed;
            foreach (double seconds in new[] { 0.0, -0.01, 0.2, double.NaN, double.PositiveInfinity }) {
                Refused(Native.chaintube_rig_update_seconds(timed.Handle, seconds, out recomputed),
                        Status.InvalidArgument, "a frame of " + seconds + " s", "seconds", "(0, 0.1]");
                double[] now = WorldPoses(timed.Handle, hose, joints);
                for (int k = 0; k < now.Length; ++k)
                    Expect(now[k] == before[k], "refused " + seconds, "the hose moved");
            }
            for (int frame = 0; frame < 30; ++frame) {
                timed.Update(1.0 / 90.0);
                plain.Update();
                double[] a = WorldPoses(timed.Handle, hose, joints), b = WorldPoses(plain.Handle, hose, joints);
                for (int k = 0; k < a.Length; ++k)
                    Expect(a[k] == b[k], "frame " + frame, "Update(1/90) differs from Update()");
            }
            Expect(timed.Update(0.1) >= 0, "0.1 s", "refused");
            Console.WriteLine("CapiTest frame_rate: " + export + ": " + compared + " checks, " + failures + " failures");
        }
        return failures == 0 ? 0 : 1;
    }

    static int RunBudget(string export)
    {
        using (Rig rig = Rig.LoadMemory(Path.GetFileName(export), File.ReadAllBytes(export))) {
            int hose = rig.FindHose("right-return"), valve = rig.FindNode("valve");
            double band, remaining;
            double[] rest = rig.RestLengths(hose, out band);
            Expect(!rig.Pending(hose, out remaining) && remaining == 0.0, "as loaded", "pending");
            Refused(Native.chaintube_rig_set_budget(rig.Handle, -1), Status.InvalidArgument, "a negative budget",
                    "newton_steps");
            int unusedPending;
            Refused(Native.chaintube_rig_hose_pending(rig.Handle, 99, out unusedPending, out remaining),
                    Status.OutOfRange, "a hose out of range", "99");

            rig.SetBudget(6);
            double[] home = rig.NodeTransform(valve), trs = (double[])home.Clone();
            trs[1] += 0.06;
            double s = Math.Sin(0.15), c = Math.Cos(0.15); // turned by 0.3 rad about z
            trs[3] = c * home[3] - s * home[4];
            trs[4] = c * home[4] + s * home[3];
            trs[5] = c * home[5] + s * home[6];
            trs[6] = c * home[6] - s * home[5];
            rig.SetNodeTransform(valve, trs);
            bool pending = rig.Pending(hose, out remaining);
            Expect(pending && remaining > 0.0, "jumped", "pending " + pending + ", remaining " + remaining);
            int frame = 0;
            while (pending && frame < 100) {
                rig.Update();
                ++frame;
                ExpectInBand(rig, hose, rest, band, "pending, frame " + frame);
                pending = rig.Pending(hose, out remaining);
            }
            Expect(!pending && remaining == 0.0, "held", "not met in 100 updates: " + remaining + " m");
            rig.SetBudget(0);
            rig.SetNodeTransform(valve, home);
            Expect(!rig.Pending(hose, out remaining), "unbounded", "the jump back is pending");
            Console.WriteLine("CapiTest budget: " + export + ": a valve jump under 6 Newton steps an update met after " +
                              frame + " updates: " + compared + " checks, " + failures + " failures");
        }
        return failures == 0 ? 0 : 1;
    }

    static int Main(string[] args)
    {
        try {
            if (args.Length == 3 && args[0] == "replay") return RunReplay(args[1], args[2]);
            if (args.Length == 2 && args[0] == "errors") return RunErrors(args[1]);
            if (args.Length == 2 && args[0] == "clip") return RunClip(args[1]);
            if (args.Length == 2 && args[0] == "actions") return RunActions(args[1]);
            if (args.Length == 2 && args[0] == "budget") return RunBudget(args[1]);
            if (args.Length == 2 && args[0] == "frame_rate") return RunFrameRate(args[1]);
            Console.Error.WriteLine("usage: CapiTest.exe replay <export.glb> <reference.txt> | errors <test-rig.glb> | " +
                                    "clip <motion-rig.glb> | actions <rig-options.glb> | budget <test-rig.glb> | " +
                                    "frame_rate <rig-options.glb>");
            return 2;
        } catch (Exception error) {
            Console.Error.WriteLine("FAIL: " + error);
            return 1;
        }
    }
}
