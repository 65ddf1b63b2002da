/* The frame's time from C (chaintube_rig_update_seconds, ABI 1.4): loads the rig-options export
 * (tests/exporters/data/rig-options.ctproj), whose hose valve-tail hangs under gravity from the
 * valve with its last point free, and
 *  - refuses a NULL rig, a frame time of 0, < 0, above 0.1 s, NaN and infinity, each with
 *    CHAINTUBE_ERROR_INVALID_ARGUMENT and a message naming `seconds`, the hose unchanged;
 *  - a frame of 1/90 s gives the same joints as chaintube_rig_update, frame by frame;
 *  - the valve driven along the same timed path (a 4 cm x 3 cm loop in 1 s, then held) at 45,
 *    72 and 120 Hz: valve-tail's joints end within 2 mm of the 90 Hz run after 15 s, every
 *    segment in its band (|l / l0 - 1| <= e + 1e-9) after every update. The tail comes to rest
 *    where it stops coming lower (lib/README.md, "Gravity at any frame rate"), which depends on
 *    rounding: 0.18 mm at most in the default build.
 *
 *   capi_frame_rate_test <rig-options.glb>
 *
 * Compiled as C99. Exit 0: every check passes; 1: a failure (each printed). */
#include "capi_check.h"
#include "chaintube/runtime_c.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define TOLERANCE 1e-9 /* relative, for the band */
#define MAX_POINTS 512
#define PI 3.14159265358979323846
#define RUN_SECONDS 15.0 /* the path (1 s), then held until every run has settled */

typedef struct run_state
{
    chaintube_rig* rig;
    int32_t tail, valve, count;
    double home[10];
} run_state;

static int open_rig(const char* file, run_state* state)
{
    chaintube_hose_info info;
    state->rig = NULL;
    if (!ok(chaintube_rig_load_file(CHAINTUBE_RUNTIME_ABI_VERSION, file, &state->rig), "load_file"))
        return 0;
    if (!ok(chaintube_rig_find_hose(state->rig, "valve-tail", &state->tail), "find_hose") ||
        !ok(chaintube_rig_find_node(state->rig, "valve", &state->valve), "find_node") ||
        !ok(chaintube_rig_hose_info(state->rig, state->tail, &info), "hose_info") ||
        !ok(chaintube_rig_node_transform(state->rig, state->valve, state->home), "node_transform"))
        return 0;
    state->count = info.joint_count;
    return info.joint_count > 1 && info.joint_count <= MAX_POINTS;
}

/* valve-tail's joint world positions (x, y, z a joint) into `points`. */
static void joints(const run_state* state, double* points)
{
    static double world[7 * MAX_POINTS];
    if (!ok(chaintube_rig_joint_poses_f64(state->rig, state->tail, NULL, 0, world, 7 * MAX_POINTS),
            "joint_poses_f64"))
        return;
    for (int32_t j = 0; j < state->count; ++j)
        memcpy(points + 3 * j, world + 7 * j, 3 * sizeof(double));
}

/* Every segment within its band (chaintube_rig_rest_lengths) after an update. */
static void expect_in_band(const double* points, const double* rest, int32_t count, double band,
                           double rate, int frame)
{
    for (int32_t s = 0; s + 1 < count; ++s) {
        const double* a = points + 3 * s;
        const double* b = points + 3 * (s + 1);
        const double length = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                                   (a[2] - b[2]) * (a[2] - b[2]));
        CHECK(fabs(length / rest[s] - 1.0) <= band + TOLERANCE,
              "%.0f Hz, frame %d: segment %d is %.12g m, rest %.12g m, band %g", rate, frame,
              (int)s, length, rest[s], band);
    }
}

/* Drives the valve along the loop at `rate` Hz for RUN_SECONDS; valve-tail's joints at the end
 * into `end`. */
static void drive(const char* file, double rate, const double* rest, double band, double* end)
{
    static double points[3 * MAX_POINTS];
    run_state state;
    const double frame = 1.0 / rate;
    const int frames = (int)floor(RUN_SECONDS * rate + 0.5);
    if (!open_rig(file, &state)) return;
    for (int k = 1; k <= frames; ++k) {
        double trs[10];
        const double t = k * frame;
        const double phase = 2.0 * PI * t;
        memcpy(trs, state.home, sizeof trs);
        if (t < 1.0) {
            trs[0] += 0.04 * sin(phase);
            trs[1] += 0.03 * (1.0 - cos(phase));
        }
        if (!ok(chaintube_rig_set_node_transform(state.rig, state.valve, trs),
                "set_node_transform") ||
            !ok(chaintube_rig_update_seconds(state.rig, frame, NULL), "update_seconds"))
            break;
        joints(&state, points);
        expect_in_band(points, rest, state.count, band, rate, k);
    }
    joints(&state, end);
    ok(chaintube_rig_destroy(state.rig), "destroy");
}

static double largest_difference(const double* a, const double* b, int32_t count)
{
    double largest = 0.0;
    for (int32_t j = 0; j < count; ++j) {
        const double dx = a[3 * j] - b[3 * j], dy = a[3 * j + 1] - b[3 * j + 1],
                     dz = a[3 * j + 2] - b[3 * j + 2];
        const double d = sqrt(dx * dx + dy * dy + dz * dz);
        if (d > largest) largest = d;
    }
    return largest;
}

int main(int argc, char** argv)
{
    static double before[3 * MAX_POINTS], after[3 * MAX_POINTS], rest[MAX_POINTS];
    static double reference[3 * MAX_POINTS], other[3 * MAX_POINTS];
    const double bad[] = {0.0, -1.0 / 90.0, 0.1000001, 1.0, NAN, INFINITY};
    const double rates[] = {45.0, 72.0, 120.0};
    run_state a, b;
    double trs[10], band = 0.0;
    chaintube_hose_info info;
    if (argc != 2) {
        fprintf(stderr, "usage: capi_frame_rate_test <rig-options.glb>\n");
        return 2;
    }
    if (!open_rig(argv[1], &a) || !open_rig(argv[1], &b)) return 1;
    if (!ok(chaintube_rig_hose_info(a.rig, a.tail, &info), "hose_info")) return 1;

    if (!ok(chaintube_rig_rest_lengths(a.rig, a.tail, rest, MAX_POINTS, &band), "rest_lengths"))
        return 1;

    /* Refusals: nothing changes. */
    refused(chaintube_rig_update_seconds(NULL, 1.0 / 90.0, NULL), CHAINTUBE_ERROR_INVALID_ARGUMENT,
            "rig is NULL", "a NULL rig");
    memcpy(trs, a.home, sizeof trs);
    trs[0] += 0.03;
    ok(chaintube_rig_set_node_transform(a.rig, a.valve, trs), "set_node_transform");
    ok(chaintube_rig_set_node_transform(b.rig, b.valve, trs), "set_node_transform");
    joints(&a, before);
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        char what[64];
        int32_t recomputed = -7;
        snprintf(what, sizeof what, "a frame of %g s", bad[i]);
        refused(chaintube_rig_update_seconds(a.rig, bad[i], &recomputed),
                CHAINTUBE_ERROR_INVALID_ARGUMENT, "seconds: expected the frame's time in (0, 0.1]",
                what);
        CHECK(recomputed == -7, "%s wrote recomputed: %d", what, (int)recomputed);
        joints(&a, after);
        CHECK(largest_difference(before, after, a.count) == 0.0, "%s moved the hose", what);
    }

    /* A frame of 1/90 s is chaintube_rig_update's. */
    for (int frame = 0; frame < 30; ++frame) {
        ok(chaintube_rig_update_seconds(a.rig, 1.0 / 90.0, NULL), "update_seconds");
        ok(chaintube_rig_update(b.rig, NULL), "update");
        joints(&a, before);
        joints(&b, after);
        CHECK(largest_difference(before, after, a.count) == 0.0,
              "frame %d: 1/90 s differs from chaintube_rig_update by %.3g m", frame,
              largest_difference(before, after, a.count));
    }
    ok(chaintube_rig_destroy(a.rig), "destroy");
    ok(chaintube_rig_destroy(b.rig), "destroy");

    /* The same timed path at 45, 72 and 120 Hz ends where the 90 Hz run does. */
    drive(argv[1], 90.0, rest, band, reference);
    for (size_t r = 0; r < sizeof rates / sizeof rates[0]; ++r) {
        double difference;
        drive(argv[1], rates[r], rest, band, other);
        difference = largest_difference(reference, other, info.joint_count);
        printf("valve-tail at %.0f Hz: %.3g m from the 90 Hz run after %.0f s\n", rates[r],
               difference, RUN_SECONDS);
        CHECK(difference <= 2e-3, "%.0f Hz ends %.3g m from the 90 Hz run", rates[r], difference);
    }

    printf("%ld checks, %d failures\n", checks, failures);
    return failures == 0 ? 0 : 1;
}
