/* The work of a frame from C (chaintube_rig_set_budget, chaintube_rig_hose_pending): loads the
 * test-rig export (right-return fixed from bracket_right to the valve) and
 *  - refuses a negative budget, a hose out of range and two NULL outputs, each with its status
 *    and a message naming the fault;
 *  - under a budget of 6 Newton steps the valve jumps 6 cm up and turns by 0.3 rad in one
 *    frame: right-return is pending with a remaining distance > 0, and the updates after it
 *    go on until it is not (within 100), every frame every segment in its band
 *    (|l / l0 - 1| <= e + 1e-9), remaining 0 once done;
 *  - without a bound (0) the jump back is not pending.
 *
 *   capi_budget_test <test-rig.glb>
 *
 * Compiled as C99. Exit 0: every check passes; 1: a failure (each printed). */
#include "capi_check.h"
#include "chaintube/runtime_c.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define TOLERANCE 1e-9 /* relative, for the band */
#define MAX_POINTS 512

/* Every segment of the hose within its band as of the last update (the joints' world
 * translations are the axis points). */
static void expect_in_band(const chaintube_rig* rig, int32_t hose, int32_t count,
                           const double* rest, double band, int frame)
{
    static double world[7 * MAX_POINTS];
    if (!ok(chaintube_rig_joint_poses_f64(rig, hose, NULL, 0, world, 7 * MAX_POINTS),
            "joint_poses_f64"))
        return;
    for (int32_t s = 0; s + 1 < count; ++s) {
        const double* a = world + 7 * s;
        const double* b = world + 7 * (s + 1);
        const double length = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                                   (a[2] - b[2]) * (a[2] - b[2]));
        CHECK(fabs(length / rest[s] - 1.0) <= band + TOLERANCE,
              "frame %d: segment %d is %.12g m, rest %.12g m, band %g", frame, (int)s, length,
              rest[s], band);
    }
}

int main(int argc, char** argv)
{
    chaintube_rig* rig = NULL;
    int32_t hose = -1, valve = -1, pending = -1, frame = 0;
    double remaining = -1.0, band = 0.0, trs[10], home[10];
    static double rest[MAX_POINTS];
    chaintube_hose_info info;
    if (argc != 2) {
        fprintf(stderr, "usage: capi_budget_test <test-rig.glb>\n");
        return 2;
    }
    if (!ok(chaintube_rig_load_file(CHAINTUBE_RUNTIME_ABI_VERSION, argv[1], &rig), "load_file"))
        return 1;
    if (!ok(chaintube_rig_find_hose(rig, "right-return", &hose), "find_hose") ||
        !ok(chaintube_rig_find_node(rig, "valve", &valve), "find_node") ||
        !ok(chaintube_rig_hose_info(rig, hose, &info), "hose_info") ||
        !ok(chaintube_rig_rest_lengths(rig, hose, rest, MAX_POINTS, &band), "rest_lengths") ||
        !ok(chaintube_rig_node_transform(rig, valve, home), "node_transform"))
        return 1;
    CHECK(info.joint_count == info.point_count, "a joint a point: %d, %d", (int)info.joint_count,
          (int)info.point_count);

    /* Refused, nothing changed. */
    refused(chaintube_rig_set_budget(rig, -1), CHAINTUBE_ERROR_INVALID_ARGUMENT, "newton_steps",
            "a negative budget");
    refused(chaintube_rig_set_budget(NULL, 16), CHAINTUBE_ERROR_INVALID_ARGUMENT, "rig",
            "a NULL rig");
    refused(chaintube_rig_hose_pending(rig, 99, &pending, &remaining), CHAINTUBE_ERROR_OUT_OF_RANGE,
            "99", "a hose out of range");
    refused(chaintube_rig_hose_pending(rig, hose, NULL, NULL), CHAINTUBE_ERROR_INVALID_ARGUMENT,
            "NULL", "two NULL outputs");
    if (ok(chaintube_rig_hose_pending(rig, hose, &pending, &remaining), "hose_pending"))
        CHECK(pending == 0 && remaining == 0.0, "nothing pending after load: %d, %g", (int)pending,
              remaining);

    /* A jump beyond a small budget: pending, then met over the next updates. */
    ok(chaintube_rig_set_budget(rig, 6), "set_budget 6");
    memcpy(trs, home, sizeof trs);
    trs[1] += 0.06;
    {
        /* the rotation turned by 0.3 rad about z: q' = (0, 0, sin 0.15, cos 0.15) * q */
        const double s = sin(0.15), c = cos(0.15);
        const double x = home[3], y = home[4], z = home[5], w = home[6];
        trs[3] = c * x - s * y;
        trs[4] = c * y + s * x;
        trs[5] = c * z + s * w;
        trs[6] = c * w - s * z;
    }
    ok(chaintube_rig_set_node_transform(rig, valve, trs), "set_node_transform");
    if (ok(chaintube_rig_hose_pending(rig, hose, &pending, &remaining), "hose_pending"))
        CHECK(pending == 1 && remaining > 0.0, "the jump is pending: %d, %g", (int)pending,
              remaining);
    for (frame = 1; frame <= 100 && pending; ++frame) {
        ok(chaintube_rig_update(rig, NULL), "update");
        expect_in_band(rig, hose, info.point_count, rest, band, frame);
        if (!ok(chaintube_rig_hose_pending(rig, hose, &pending, &remaining), "hose_pending")) break;
        CHECK(isfinite(remaining) && remaining >= 0.0, "frame %d: remaining %g", frame, remaining);
    }
    CHECK(pending == 0 && remaining == 0.0, "met within 100 updates: pending %d, %g m after %d",
          (int)pending, remaining, frame);

    /* Without a bound the jump back is met in its frame. */
    ok(chaintube_rig_set_budget(rig, 0), "set_budget 0");
    ok(chaintube_rig_set_node_transform(rig, valve, home), "set_node_transform back");
    if (ok(chaintube_rig_hose_pending(rig, hose, NULL, &remaining), "hose_pending remaining"))
        CHECK(remaining == 0.0, "unbounded: nothing remaining, %g", remaining);
    if (ok(chaintube_rig_hose_pending(rig, hose, &pending, NULL), "hose_pending pending"))
        CHECK(pending == 0, "unbounded: not pending");

    chaintube_rig_destroy(rig);
    printf("%ld checks, %d failures; met after %d updates\n", checks, failures, frame - 1);
    return failures ? 1 : 0;
}
