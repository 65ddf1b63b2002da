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
                "wrong ABI major", "ABI 2.0", "ABI 1.0");
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
        }
        Console.WriteLine("CapiTest errors: " + compared + " checks, " + failures + " failures");
        return failures == 0 ? 0 : 1;
    }

    static int Main(string[] args)
    {
        try {
            if (args.Length == 3 && args[0] == "replay") return RunReplay(args[1], args[2]);
            if (args.Length == 2 && args[0] == "errors") return RunErrors(args[1]);
            Console.Error.WriteLine("usage: CapiTest.exe replay <export.glb> <reference.txt> | errors <test-rig.glb>");
            return 2;
        } catch (Exception error) {
            Console.Error.WriteLine("FAIL: " + error);
            return 1;
        }
    }
}
