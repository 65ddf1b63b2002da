/* An end unplugged and plugged into another part, from C: loads the rig-options export
 * (tests/exporters/data/rig-options.ctproj), whose hose valve-tail hangs under gravity from the
 * valve with its last point free, and plays a scenario through chaintube/runtime_c.h:
 *  - a hand holds the free end where it is, the valve end is unplugged
 *    (chaintube_rig_detach_end): its attachment reads attached 0 and every point is grabbable;
 *  - ten updates: the unplugged end falls (more than 1 mm), every frame every segment within
 *    its band (|l / l0 - 1| <= e + 1e-9) and no frame INFEASIBLE;
 *  - refused, each with its status and a message naming the fault, the rig unchanged: an
 *    attachment already detached or out of range, a hose or node out of range, an end other
 *    than 0 or 1, a NaN or NULL pose, a zero rotation;
 *  - the end is plugged into bracket_left (chaintube_rig_attach_end) 1 cm above where it hangs,
 *    along the bracket's +z: the end point is there (1e-9 m), the end segment along that axis,
 *    the band holds, the new attachment is index 1, and plugging the same end again is refused;
 *  - the bracket moves 2 cm a frame, three frames: the end stays at the pose on the bracket
 *    (its world transform composed here from the nodes' local transforms), status OK, band
 *    held;
 *  - bracket-loop is cut at its middle (chaintube_rig_cut): refused at an end, beyond the last
 *    point, on a hose out of range and at a fixed point; then cut, the new hose is the next
 *    index, the pieces have their points, an id returned before stays valid, and every joint of
 *    the skin is posed by exactly one piece (the new hose's first joint node -1);
 *  - valve-tail, let go, is paid out 5 cm at its plugged end (chaintube_rig_reel, 0.5 m/s at
 *    90 Hz) and reeled back as far as it goes: the joint count constant, the rest length what
 *    was paid;
 *    refused, each with its status and message, the rest length unchanged: end 2, bounds
 *    inverted, a NaN length, the free end, a clip out of range, a hose out of range; the axis
 *    points into NULL or a short buffer.
 *
 *   capi_actions_test <rig-options.glb>
 *
 * Compiled as C99. Exit 0: every check passes; 1: a failure (each printed). */
#include "capi_check.h"
#include "chaintube/runtime_c.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define TOLERANCE 1e-9 /* metres, and relative for the band */
#define MAX_POINTS 64

/* The hose's axis points (world metres, 3 a point) as of the last update: the joints' world
 * translations are the ring centres, the axis points. */
static int points_of(const chaintube_rig* rig, int32_t hose, int32_t count, double* points)
{
    double world[7 * MAX_POINTS];
    if (!ok(chaintube_rig_joint_poses_f64(rig, hose, NULL, 0, world, 7 * MAX_POINTS),
            "joint_poses_f64"))
        return 0;
    for (int32_t i = 0; i < count; ++i)
        for (int k = 0; k < 3; ++k)
            points[3 * i + k] = world[7 * i + k];
    return 1;
}

static double distance(const double* a, const double* b)
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                (a[2] - b[2]) * (a[2] - b[2]));
}

/* Every segment within its band after an update. */
static void expect_in_band(const chaintube_rig* rig, int32_t hose, int32_t count,
                           const double* rest, double band, const char* when, int frame)
{
    double points[3 * MAX_POINTS];
    if (!points_of(rig, hose, count, points)) return;
    for (int32_t s = 0; s + 1 < count; ++s) {
        const double length = distance(points + 3 * s, points + 3 * (s + 1));
        CHECK(fabs(length / rest[s] - 1.0) <= band + TOLERANCE,
              "%s, frame %d: segment %d is %.12g m, rest %.12g m, band %g", when, frame, (int)s,
              length, rest[s], band);
    }
}

/* A node's world transform as a column-major 4x4 matrix: the product of its and its
 * ancestors' local T * R * S. */
static void world_of(const chaintube_rig* rig, int32_t node, double m[16])
{
    double local[10], l[16], product[16];
    chaintube_node_info info;
    for (int k = 0; k < 16; ++k)
        m[k] = k % 5 == 0 ? 1.0 : 0.0;
    while (node >= 0) {
        double x, y, z, w;
        if (!ok(chaintube_rig_node_transform(rig, node, local), "node_transform") ||
            !ok(chaintube_rig_node_info(rig, node, &info), "node_info"))
            return;
        x = local[3], y = local[4], z = local[5], w = local[6];
        /* rotation columns, each scaled */
        l[0] = (1 - 2 * (y * y + z * z)) * local[7];
        l[1] = (2 * (x * y + z * w)) * local[7];
        l[2] = (2 * (x * z - y * w)) * local[7];
        l[4] = (2 * (x * y - z * w)) * local[8];
        l[5] = (1 - 2 * (x * x + z * z)) * local[8];
        l[6] = (2 * (y * z + x * w)) * local[8];
        l[8] = (2 * (x * z + y * w)) * local[9];
        l[9] = (2 * (y * z - x * w)) * local[9];
        l[10] = (1 - 2 * (x * x + y * y)) * local[9];
        l[3] = l[7] = l[11] = 0.0;
        l[12] = local[0], l[13] = local[1], l[14] = local[2], l[15] = 1.0;
        /* m = l * m: the parent's transform applies after the child's */
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) {
                double sum = 0.0;
                for (int k = 0; k < 4; ++k)
                    sum += l[4 * k + r] * m[4 * c + k];
                product[4 * c + r] = sum;
            }
        memcpy(m, product, sizeof product);
        node = info.parent;
    }
}

/* The rigid part of a world transform (no shear): axes[9] the unit columns, origin[3]. */
static void rigid_of(const double m[16], double axes[9], double origin[3])
{
    for (int c = 0; c < 3; ++c) {
        const double length =
            sqrt(m[4 * c] * m[4 * c] + m[4 * c + 1] * m[4 * c + 1] + m[4 * c + 2] * m[4 * c + 2]);
        for (int r = 0; r < 3; ++r)
            axes[3 * c + r] = m[4 * c + r] / length;
        origin[c] = m[12 + c];
    }
}

/* The world position of local point p on a node's rigid frame. */
static void on_node(const chaintube_rig* rig, int32_t node, const double p[3], double out[3])
{
    double m[16], axes[9], origin[3];
    world_of(rig, node, m);
    rigid_of(m, axes, origin);
    for (int r = 0; r < 3; ++r)
        out[r] = origin[r] + axes[r] * p[0] + axes[3 + r] * p[1] + axes[6 + r] * p[2];
}

int main(int argc, char** argv)
{
    chaintube_rig* rig = NULL;
    chaintube_hose_info info;
    chaintube_hose_result result;
    chaintube_attachment_pull pull;
    int32_t tail = -1, valve = -1, bracket = -1, count = 0, nodes = 0, index = -1, n;
    double rest[MAX_POINTS], band = 0.0, points[3 * MAX_POINTS];
    double target[3], start_height, drop, pose[7], bad[7];
    double m[16], axes[9], origin[3], socket[3], expected[3], trs[10];
    if (argc != 2) {
        fprintf(stderr, "usage: capi_actions_test <rig-options.glb>\n");
        return 2;
    }
    if (!ok(chaintube_rig_load_file(CHAINTUBE_RUNTIME_ABI_VERSION, argv[1], &rig), "load_file"))
        return 1;
    if (!ok(chaintube_rig_find_hose(rig, "valve-tail", &tail), "find_hose valve-tail") ||
        !ok(chaintube_rig_find_node(rig, "valve", &valve), "find_node valve") ||
        !ok(chaintube_rig_find_node(rig, "bracket_left", &bracket), "find_node bracket_left") ||
        !ok(chaintube_rig_hose_info(rig, tail, &info), "hose_info") ||
        !ok(chaintube_rig_node_count(rig, &nodes), "node_count") ||
        !ok(chaintube_rig_rest_lengths(rig, tail, rest, MAX_POINTS, &band), "rest_lengths"))
        return 1;
    n = info.point_count;
    CHECK(n <= MAX_POINTS && info.has_gravity, "%d points, gravity %d", (int)n,
          (int)info.has_gravity);
    CHECK(ok(chaintube_rig_attachment_count(rig, tail, &count), "attachment_count") && count == 1,
          "%d attachments", (int)count);
    CHECK(ok(chaintube_rig_attachment_pull(rig, tail, 0, 0.0, &pull), "attachment_pull") &&
              pull.node == valve && pull.attached == 1 && pull.first_point == 0 &&
              pull.last_point == 1,
          "attachment 0: node %d, attached %d, points %d to %d", (int)pull.node, (int)pull.attached,
          (int)pull.first_point, (int)pull.last_point);
    CHECK(info.grabbable_count == n - 2, "%d grabbable", (int)info.grabbable_count);

    /* Hold the free end where it is; unplug the valve end. */
    if (!points_of(rig, tail, n, points)) return 1;
    memcpy(target, points + 3 * (n - 1), sizeof target);
    ok(chaintube_rig_grab(rig, tail, n - 1, target, &result), "grab the free end");
    ok(chaintube_rig_update(rig, NULL), "update");
    ok(chaintube_rig_detach_end(rig, tail, 0, &result), "detach_end");
    CHECK(ok(chaintube_rig_attachment_pull(rig, tail, 0, 0.0, &pull), "attachment_pull") &&
              pull.attached == 0,
          "attached %d after detach_end", (int)pull.attached);
    CHECK(ok(chaintube_rig_hose_info(rig, tail, &info), "hose_info") && info.grabbable_count == n,
          "%d grabbable after detach_end, expected %d", (int)info.grabbable_count, (int)n);
    if (!points_of(rig, tail, n, points)) return 1;
    start_height = points[1];
    for (int frame = 0; frame < 10; ++frame) {
        ok(chaintube_rig_update(rig, NULL), "update");
        expect_in_band(rig, tail, n, rest, band, "falling", frame);
        CHECK(ok(chaintube_rig_hose_result(rig, tail, &result), "hose_result") &&
                  result.status != CHAINTUBE_HOSE_INFEASIBLE,
              "frame %d: status %d", frame, (int)result.status);
    }
    if (!points_of(rig, tail, n, points)) return 1;
    drop = start_height - points[1];
    CHECK(drop > 1e-3, "the unplugged end fell %g m", drop);

    /* Refusals: status, message, nothing changed. */
    pose[0] = pose[1] = pose[2] = 0.0;
    pose[3] = pose[4] = pose[5] = 0.0;
    pose[6] = 1.0;
    index = 12345;
    refused(chaintube_rig_detach_end(rig, tail, 0, NULL), CHAINTUBE_ERROR_INVALID_ARGUMENT,
            "already detached", "detach a detached end");
    refused(chaintube_rig_detach_end(rig, tail, 1, NULL), CHAINTUBE_ERROR_OUT_OF_RANGE,
            "attachment 1 is out of range", "detach attachment 1");
    refused(chaintube_rig_detach_end(rig, 99, 0, NULL), CHAINTUBE_ERROR_OUT_OF_RANGE, "hose 99",
            "detach on hose 99");
    refused(chaintube_rig_detach_end(NULL, tail, 0, NULL), CHAINTUBE_ERROR_INVALID_ARGUMENT,
            "rig is NULL", "detach on NULL");
    refused(chaintube_rig_attach_end(rig, tail, 2, bracket, pose, &index, NULL),
            CHAINTUBE_ERROR_INVALID_ARGUMENT, "end 2", "attach end 2");
    refused(chaintube_rig_attach_end(rig, tail, 0, nodes, pose, &index, NULL),
            CHAINTUBE_ERROR_OUT_OF_RANGE, "is out of range", "attach to a node out of range");
    refused(chaintube_rig_attach_end(rig, 7, 0, bracket, pose, &index, NULL),
            CHAINTUBE_ERROR_OUT_OF_RANGE, "hose 7", "attach on hose 7");
    memcpy(bad, pose, sizeof bad);
    bad[1] = nan("");
    refused(chaintube_rig_attach_end(rig, tail, 0, bracket, bad, &index, NULL),
            CHAINTUBE_ERROR_INVALID_ARGUMENT, "pose[1] (translation y) is NaN", "NaN pose");
    bad[1] = 0.0;
    bad[6] = 0.0;
    refused(chaintube_rig_attach_end(rig, tail, 0, bracket, bad, &index, NULL),
            CHAINTUBE_ERROR_INVALID_ARGUMENT, "unit quaternion", "zero rotation");
    refused(chaintube_rig_attach_end(rig, tail, 0, bracket, NULL, &index, NULL),
            CHAINTUBE_ERROR_INVALID_ARGUMENT, "pose is NULL", "NULL pose");
    ok(chaintube_rig_update(rig, NULL), "update");
    CHECK(index == 12345, "a refused call wrote the attachment index");
    CHECK(ok(chaintube_rig_attachment_count(rig, tail, &count), "attachment_count") && count == 1,
          "%d attachments after refused calls", (int)count);

    /* Plug the end into bracket_left, 1 cm above where it hangs, along the bracket's +z. */
    if (!points_of(rig, tail, n, points)) return 1;
    socket[0] = points[0];
    socket[1] = points[1] + 0.01;
    socket[2] = points[2];
    world_of(rig, bracket, m);
    rigid_of(m, axes, origin);
    for (int c = 0; c < 3; ++c) /* the socket in the bracket's rigid frame */
        pose[c] = axes[3 * c] * (socket[0] - origin[0]) +
                  axes[3 * c + 1] * (socket[1] - origin[1]) +
                  axes[3 * c + 2] * (socket[2] - origin[2]);
    CHECK(
        ok(chaintube_rig_attach_end(rig, tail, 0, bracket, pose, &index, &result), "attach_end") &&
            result.status == CHAINTUBE_HOSE_OK && index == 1,
        "status %d, index %d", (int)result.status, (int)index);
    CHECK(ok(chaintube_rig_attachment_count(rig, tail, &count), "attachment_count") && count == 2,
          "%d attachments after attach_end", (int)count);
    CHECK(ok(chaintube_rig_attachment_pull(rig, tail, 1, 0.0, &pull), "attachment_pull") &&
              pull.node == bracket && pull.attached == 1 && pull.first_point == 0 &&
              pull.last_point == 1,
          "attachment 1: node %d, attached %d, points %d to %d", (int)pull.node, (int)pull.attached,
          (int)pull.first_point, (int)pull.last_point);
    ok(chaintube_rig_update(rig, NULL), "update");
    if (!points_of(rig, tail, n, points)) return 1;
    CHECK(distance(points, socket) < TOLERANCE, "the plugged end is %g m from the socket",
          distance(points, socket));
    {
        const double length = distance(points, points + 3);
        double along = 0.0;
        for (int k = 0; k < 3; ++k)
            along += (points[k] - points[3 + k]) / length * axes[6 + k];
        CHECK(along > 1.0 - TOLERANCE, "the end segment is %.12g along the bracket's z", along);
    }
    expect_in_band(rig, tail, n, rest, band, "plugged", 0);
    CHECK(ok(chaintube_rig_hose_info(rig, tail, &info), "hose_info") &&
              info.grabbable_count == n - 2,
          "%d grabbable after attach_end (the hand still holds the last point)",
          (int)info.grabbable_count);
    refused(chaintube_rig_attach_end(rig, tail, 0, valve, pose, &index, NULL),
            CHAINTUBE_ERROR_INVALID_ARGUMENT, "already attached", "plug the same end again");
    CHECK(ok(chaintube_rig_attachment_count(rig, tail, &count), "attachment_count") && count == 2,
          "%d attachments after a refused attach_end", (int)count);

    /* The bracket moves: the plugged end goes with it. */
    ok(chaintube_rig_node_transform(rig, bracket, trs), "node_transform");
    for (int frame = 0; frame < 3; ++frame) {
        trs[0] += 0.02;
        ok(chaintube_rig_set_node_transform(rig, bracket, trs), "set_node_transform");
        ok(chaintube_rig_update(rig, NULL), "update");
        on_node(rig, bracket, pose, expected);
        if (points_of(rig, tail, n, points))
            CHECK(distance(points, expected) < TOLERANCE,
                  "frame %d: the plugged end is %g m from its place on the bracket", frame,
                  distance(points, expected));
        CHECK(ok(chaintube_rig_hose_result(rig, tail, &result), "hose_result") &&
                  result.status == CHAINTUBE_HOSE_OK,
              "frame %d: status %d", frame, (int)result.status);
        expect_in_band(rig, tail, n, rest, band, "bracket moved", frame);
    }
    /* Cut bracket-loop in two at its middle. */
    {
        int32_t loop = -1, hoses = 0, piece = -1, nodes_before[MAX_POINTS], nodes_after[MAX_POINTS];
        chaintube_hose_info loop_info, piece_info;
        const char* old_id;
        if (ok(chaintube_rig_find_hose(rig, "bracket-loop", &loop), "find_hose bracket-loop") &&
            ok(chaintube_rig_hose_info(rig, loop, &loop_info), "hose_info") &&
            ok(chaintube_rig_hose_count(rig, &hoses), "hose_count") &&
            ok(chaintube_rig_joint_nodes(rig, loop, nodes_before, MAX_POINTS), "joint_nodes")) {
            const int32_t middle = loop_info.point_count / 2, count_before = loop_info.point_count;
            old_id = loop_info.id;
            piece = 12345;
            refused(chaintube_rig_cut(rig, loop, 0, &piece), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                    "expected an interior point", "cut at point 0");
            refused(chaintube_rig_cut(rig, loop, count_before - 1, &piece),
                    CHAINTUBE_ERROR_INVALID_ARGUMENT, "expected an interior point",
                    "cut at the last point");
            refused(chaintube_rig_cut(rig, loop, count_before, &piece),
                    CHAINTUBE_ERROR_OUT_OF_RANGE, "is out of range", "cut beyond the last point");
            refused(chaintube_rig_cut(rig, hoses, 1, &piece), CHAINTUBE_ERROR_OUT_OF_RANGE,
                    "is out of range", "cut a hose out of range");
            refused(chaintube_rig_cut(rig, loop, 1, &piece), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                    "point 1", "cut at a fixed point");
            CHECK(piece == 12345, "a refused cut wrote the new hose");
            CHECK(ok(chaintube_rig_hose_count(rig, &count), "hose_count") && count == hoses,
                  "%d hoses after refused cuts", (int)count);
            CHECK(ok(chaintube_rig_cut(rig, loop, middle, &piece), "cut") && piece == hoses,
                  "new hose %d, expected %d", (int)piece, (int)hoses);
            CHECK(strcmp(old_id, "bracket-loop") == 0, "an id returned before the cut changed");
            if (ok(chaintube_rig_hose_info(rig, loop, &loop_info), "hose_info") &&
                ok(chaintube_rig_hose_info(rig, piece, &piece_info), "hose_info")) {
                CHECK(loop_info.point_count == middle + 1 &&
                          piece_info.point_count == count_before - middle,
                      "pieces of %d and %d points", (int)loop_info.point_count,
                      (int)piece_info.point_count);
                CHECK(strstr(piece_info.id, "bracket-loop~") == piece_info.id, "new id \"%s\"",
                      piece_info.id);
                CHECK(piece_info.skin == loop_info.skin &&
                          piece_info.mesh_node == loop_info.mesh_node,
                      "the new hose's skin %d, mesh node %d", (int)piece_info.skin,
                      (int)piece_info.mesh_node);
                /* Every joint is posed by exactly one piece, the cut point's by the first. */
                if (ok(chaintube_rig_joint_nodes(rig, loop, nodes_after, MAX_POINTS),
                       "joint_nodes") &&
                    ok(chaintube_rig_joint_nodes(rig, piece, nodes_after + middle + 1,
                                                 MAX_POINTS - (middle + 1)),
                       "joint_nodes")) {
                    CHECK(nodes_after[middle + 1] == -1, "the new hose's first joint node is %d",
                          (int)nodes_after[middle + 1]);
                    for (int32_t j = 0; j < count_before; ++j) {
                        const int32_t posed = j <= middle ? nodes_after[j] : nodes_after[j + 1];
                        CHECK(posed == nodes_before[j], "joint %d: node %d, expected %d", (int)j,
                              (int)posed, (int)nodes_before[j]);
                    }
                }
                CHECK(ok(chaintube_rig_attachment_count(rig, piece, &count), "attachment_count") &&
                          count == 1,
                      "the new hose has %d attachments", (int)count);
            }
            /* Reel: valve-tail, let go by the hand, plugged into the bracket at end 0, pays out
             * 5 cm at 0.5 m/s at 90 Hz and takes it back (a clamped frame's rest is paid the next
             * frame); the joint count stays, refusals change nothing. */
            {
                chaintube_reel_result reel;
                chaintube_hose_info before, now;
                double axis[3 * 3 * MAX_POINTS], paid_in = 0.0;
                ok(chaintube_rig_release(rig, tail), "release");
                if (ok(chaintube_rig_hose_info(rig, tail, &before), "hose_info")) {
                    for (int direction = 1; direction >= -1; direction -= 2) {
                        double left = 0.05;
                        for (int frame = 0; frame < 60 && left > 1e-12; ++frame) {
                            const double step = left < 0.5 / 90 ? left : 0.5 / 90;
                            if (!ok(chaintube_rig_reel(rig, tail, 0, -1, direction * step, 0.0,
                                                       10.0, &reel),
                                    "reel"))
                                break;
                            left -= fabs(reel.paid);
                            ok(chaintube_rig_update(rig, NULL), "update");
                            CHECK(ok(chaintube_rig_hose_info(rig, tail, &now), "hose_info") &&
                                      now.joint_count == before.joint_count &&
                                      now.point_count == reel.point_count &&
                                      now.point_count <= 3 * MAX_POINTS,
                                  "reel frame %d: %d joints, %d points", frame,
                                  (int)now.joint_count, (int)now.point_count);
                            ok(chaintube_rig_axis_points(rig, tail, axis, 9 * MAX_POINTS),
                               "axis_points");
                        }
                        /* Paid out in full; reeling in, a frame whose step would move a point
                         * more than twice its length waits (lib/README.md): as far as it goes. */
                        if (direction > 0)
                            CHECK(left <= 1e-12, "paying out: %g m left", left);
                        else
                            paid_in = 0.05 - left;
                    }
                    CHECK(ok(chaintube_rig_hose_info(rig, tail, &now), "hose_info") &&
                              paid_in > 0.0 &&
                              fabs(now.rest_length - (before.rest_length + 0.05 - paid_in)) <
                                  TOLERANCE,
                          "reeled back %g m: %.12g m; expected %.12g m", paid_in, now.rest_length,
                          before.rest_length + 0.05 - paid_in);
                    before = now;
                    refused(chaintube_rig_reel(rig, tail, 2, -1, 0.01, 0.0, 10.0, &reel),
                            CHAINTUBE_ERROR_INVALID_ARGUMENT, "end 2", "reel at end 2");
                    refused(chaintube_rig_reel(rig, tail, 0, -1, 0.01, 2.0, 1.0, &reel),
                            CHAINTUBE_ERROR_INVALID_ARGUMENT, "maxLength", "reel bounds inverted");
                    refused(chaintube_rig_reel(rig, tail, 0, -1, nan(""), 0.0, 10.0, &reel),
                            CHAINTUBE_ERROR_INVALID_ARGUMENT, "reel length", "reel a NaN length");
                    refused(chaintube_rig_reel(rig, tail, 1, -1, 0.01, 0.0, 10.0, &reel),
                            CHAINTUBE_ERROR_INVALID_ARGUMENT, "expected an end fixed",
                            "reel at the free end");
                    refused(chaintube_rig_reel(rig, tail, 0, 0, 0.01, 0.0, 10.0, &reel),
                            CHAINTUBE_ERROR_OUT_OF_RANGE, "clip 0 is out of range",
                            "reel through a clip out of range");
                    refused(chaintube_rig_reel(rig, 99, 0, -1, 0.01, 0.0, 10.0, &reel),
                            CHAINTUBE_ERROR_OUT_OF_RANGE, "hose 99", "reel hose 99");
                    refused(chaintube_rig_axis_points(rig, tail, NULL, 9 * MAX_POINTS),
                            CHAINTUBE_ERROR_INVALID_ARGUMENT, "points is NULL",
                            "axis points into NULL");
                    refused(chaintube_rig_axis_points(rig, tail, axis, 3),
                            CHAINTUBE_ERROR_BUFFER_TOO_SMALL, "points has room for 3",
                            "axis points into a short buffer");
                    CHECK(ok(chaintube_rig_hose_info(rig, tail, &now), "hose_info") &&
                              fabs(now.rest_length - before.rest_length) < TOLERANCE,
                          "a refused reel changed the rest length to %.12g", now.rest_length);
                }
            }
        }
    }
    ok(chaintube_rig_destroy(rig), "destroy");
    printf("capi_actions_test: valve-tail unplugged, fell %.4g m in 10 updates, plugged into "
           "bracket_left and followed it 0.06 m: %ld checks, %d failures\n",
           drop, checks, failures);
    return failures == 0 ? 0 : 1;
}
