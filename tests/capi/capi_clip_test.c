/* A hose through clips, from C: loads the motion-rig export (samples/motion-rig.ctproj), whose
 * cable carriage-cable is clamped on the base plate and runs through a sliding clip on the
 * carriage and a guide clip on the plate, then slides the carriage along x as a scenario does
 * (chaintube_rig_set_node_transform, 5 mm a frame): out to +50 mm, back to -50 mm and home to 0.
 * After every update it checks the cable:
 *  - the frame's status is CHAINTUBE_HOSE_OK, length and angle violations within 1e-9 (the
 *    library holds its constraints to 1e-9, not to the last bit);
 *  - the hose passes through every clip's centre along its axis: the held segment's two points
 *    lie on the axis at their rest distances from the centre (1e-9 m), the clip's gap is 0, and
 *    the carriage's clip has moved with the carriage (1e-9 m);
 *  - every segment is within its band: |l / l0 - 1| <= e (+1e-9);
 *  - the length is conserved: the rest lengths are as loaded, their sum is the hose's
 *    rest_length, each slide lies within its end stops and on its held segment, and the hose's
 *    arc length from point 0 to each centre is its slide within the band;
 * and that the cable slid through the carriage's clip: at least 40 mm each way (the side the
 * carriage moves away from may stretch by the band, 2 % of about 0.33 m, no more). It also
 * checks the refusals: clip index out of range, NULL outputs, a short rest-length buffer, a
 * hose without clips, and a grab of a point the clip has slid onto (a grabbable point, held
 * now: CHAINTUBE_ERROR_NOT_GRABBABLE, nothing changed). A point the carriage's clip held as
 * loaded and has let go of is grabbed (where it is: status OK, nothing moves) and released.
 *
 *   capi_clip_test <motion-rig.glb>
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
#define MAX_CLIPS 4

static double distance(const double* a, const double* b)
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                (a[2] - b[2]) * (a[2] - b[2]));
}

/* The cable as loaded: what must not change. */
typedef struct
{
    int32_t hose, points, clips, carriage_clip;
    double rest[MAX_POINTS];
    double prefix[MAX_POINTS + 1]; /* rest arc length from point 0 to each point */
    double band, rest_length;
} cable;

/* Checks the cable after an update; returns the carriage clip's slide and centre. */
static double check_cable(const chaintube_rig* rig, const cable* c, const char* when,
                          double carriage_centre[3])
{
    double world[7 * MAX_POINTS];
    double p[MAX_POINTS][3];
    double rest[MAX_POINTS];
    double band = -1.0, carriage_slide = -1.0;
    chaintube_hose_result result;
    chaintube_hose_info info;
    if (!ok(chaintube_rig_hose_result(rig, c->hose, &result), "chaintube_rig_hose_result") ||
        !ok(chaintube_rig_hose_info(rig, c->hose, &info), "chaintube_rig_hose_info") ||
        !ok(chaintube_rig_joint_poses_f64(rig, c->hose, NULL, 0, world, 7 * MAX_POINTS),
            "chaintube_rig_joint_poses_f64") ||
        !ok(chaintube_rig_rest_lengths(rig, c->hose, rest, MAX_POINTS, &band),
            "chaintube_rig_rest_lengths"))
        return -1.0;
    CHECK(result.status == CHAINTUBE_HOSE_OK, "%s: status %d", when, (int)result.status);
    CHECK(result.length_violation <= TOLERANCE && result.angle_violation <= TOLERANCE,
          "%s: length violation %g, angle violation %g", when, result.length_violation,
          result.angle_violation);
    CHECK(info.rest_length == c->rest_length, "%s: rest length %.17g, loaded %.17g", when,
          info.rest_length, c->rest_length);
    CHECK(band == c->band, "%s: band %g, loaded %g", when, band, c->band);
    for (int i = 0; i < c->points; ++i)
        memcpy(p[i], world + 7 * i, sizeof p[i]);
    for (int s = 0; s + 1 < c->points; ++s) {
        const double stretch = distance(p[s + 1], p[s]) / c->rest[s] - 1.0;
        CHECK(rest[s] == c->rest[s], "%s: segment %d rest length %.17g, loaded %.17g", when, s,
              rest[s], c->rest[s]);
        CHECK(fabs(stretch) <= c->band + TOLERANCE, "%s: segment %d stretched %.3g %% (band %g %%)",
              when, s, 100.0 * stretch, 100.0 * c->band);
    }
    for (int32_t k = 0; k < c->clips; ++k) {
        chaintube_clip_info clip;
        double along = 0.0, arc = 0.0;
        int j;
        if (!ok(chaintube_rig_clip_info(rig, c->hose, k, &clip), "chaintube_rig_clip_info"))
            continue;
        j = clip.segment;
        CHECK(j >= 0 && j + 1 < c->points, "%s: clip %d segment %d", when, (int)k, j);
        if (j < 0 || j + 1 >= c->points) continue;
        CHECK(fabs(sqrt(clip.axis[0] * clip.axis[0] + clip.axis[1] * clip.axis[1] +
                        clip.axis[2] * clip.axis[2]) -
                   1.0) <= TOLERANCE,
              "%s: clip %d axis not unit", when, (int)k);
        CHECK(clip.gap <= TOLERANCE, "%s: clip %d gap %g m", when, (int)k, clip.gap);
        CHECK(clip.slide_min <= clip.slide && clip.slide <= clip.slide_max,
              "%s: clip %d slide %.9g outside its stops %g ... %g", when, (int)k, clip.slide,
              clip.slide_min, clip.slide_max);
        CHECK(c->prefix[j] <= clip.slide + TOLERANCE && clip.slide <= c->prefix[j + 1] + TOLERANCE,
              "%s: clip %d slide %.9g is not on its segment %d (%.9g ... %.9g)", when, (int)k,
              clip.slide, j, c->prefix[j], c->prefix[j + 1]);
        /* Through the centre along the axis: each held point at its rest distance from it. */
        along = clip.slide - c->prefix[j];
        for (int a = 0; a < 3; ++a) {
            const double first = clip.centre[a] - along * clip.axis[a];
            const double second = clip.centre[a] + (c->rest[j] - along) * clip.axis[a];
            CHECK(fabs(p[j][a] - first) <= TOLERANCE && fabs(p[j + 1][a] - second) <= TOLERANCE,
                  "%s: clip %d: point %d or %d off the clip's axis (coordinate %d: %.12g, %.12g; "
                  "expected %.12g, %.12g)",
                  when, (int)k, j, j + 1, a, p[j][a], p[j + 1][a], first, second);
        }
        /* The hose's arc from point 0 to the centre is the slide within the band. */
        for (int s = 0; s < j; ++s)
            arc += distance(p[s + 1], p[s]);
        arc += along;
        CHECK(fabs(arc / clip.slide - 1.0) <= c->band + TOLERANCE,
              "%s: clip %d: arc length %.9g m to the centre for a slide of %.9g m", when, (int)k,
              arc, clip.slide);
        if (k == c->carriage_clip) {
            carriage_slide = clip.slide;
            memcpy(carriage_centre, clip.centre, 3 * sizeof(double));
        }
    }
    return carriage_slide;
}

static void check_refusals(chaintube_rig* rig, const cable* c, int32_t other_hose)
{
    chaintube_clip_info info;
    int32_t count = -1;
    double rest[MAX_POINTS];
    double band = 0.0;
    refused(chaintube_rig_clip_info(rig, c->hose, c->clips, &info), CHAINTUBE_ERROR_OUT_OF_RANGE,
            "clip 2 is out of range", "clip out of range");
    refused(chaintube_rig_clip_info(rig, c->hose, -1, &info), CHAINTUBE_ERROR_OUT_OF_RANGE,
            "carriage-cable", "negative clip");
    refused(chaintube_rig_clip_info(rig, c->hose, 0, NULL), CHAINTUBE_ERROR_INVALID_ARGUMENT,
            "info is NULL", "NULL info");
    refused(chaintube_rig_clip_info(NULL, c->hose, 0, &info), CHAINTUBE_ERROR_INVALID_ARGUMENT,
            "rig is NULL", "NULL rig");
    refused(chaintube_rig_clip_count(rig, c->hose, NULL), CHAINTUBE_ERROR_INVALID_ARGUMENT,
            "count is NULL", "NULL count");
    refused(chaintube_rig_clip_count(rig, 99, &count), CHAINTUBE_ERROR_OUT_OF_RANGE,
            "hose 99 is out of range", "hose out of range");
    refused(chaintube_rig_rest_lengths(rig, c->hose, rest, c->points - 2, NULL),
            CHAINTUBE_ERROR_BUFFER_TOO_SMALL, "rest_lengths has room for 23", "short buffer");
    refused(chaintube_rig_rest_lengths(rig, c->hose, NULL, 0, NULL),
            CHAINTUBE_ERROR_INVALID_ARGUMENT, "both NULL", "no output");
    if (ok(chaintube_rig_rest_lengths(rig, c->hose, NULL, 0, &band), "band alone"))
        CHECK(band == c->band, "band alone %g", band);
    if (ok(chaintube_rig_clip_count(rig, other_hose, &count), "clip count of another hose"))
        CHECK(count == 0, "a hose without clips has %d", (int)count);
    refused(chaintube_rig_clip_info(rig, other_hose, 0, &info), CHAINTUBE_ERROR_OUT_OF_RANGE,
            "has 0 clips", "a hose without clips");
}

/* A point the carriage's clip holds now cannot be grabbed, though the export listed it as
 * grabbable (the clip held other points then); returns how many such points were tried. */
static int check_held_points_refuse_grabs(chaintube_rig* rig, const cable* c)
{
    chaintube_clip_info clip;
    int32_t grabbable[MAX_POINTS];
    chaintube_hose_info info;
    int tried = 0;
    if (!ok(chaintube_rig_hose_info(rig, c->hose, &info), "hose info") ||
        !ok(chaintube_rig_grabbable_points(rig, c->hose, grabbable, MAX_POINTS), "grabbable") ||
        !ok(chaintube_rig_clip_info(rig, c->hose, c->carriage_clip, &clip), "clip info"))
        return 0;
    for (int32_t g = 0; g < info.grabbable_count; ++g)
        if (grabbable[g] == clip.segment || grabbable[g] == clip.segment + 1) {
            double target[3];
            memcpy(target, clip.centre, sizeof target);
            target[1] += 0.01;
            refused(chaintube_rig_grab(rig, c->hose, grabbable[g], target, NULL),
                    CHAINTUBE_ERROR_NOT_GRABBABLE, "is held by a clip now", "a point a clip holds");
            ++tried;
        }
    return tried;
}

/* The points the carriage's clip held as loaded (home_segment, home_segment + 1) that it no
 * longer holds can be grabbed: each is grabbed where it is (status OK, no point moves more
 * than 1e-9 m) and released. Returns how many were grabbed. */
static int check_released_points_grab(chaintube_rig* rig, const cable* c, int32_t home_segment)
{
    chaintube_clip_info clip;
    double before[7 * MAX_POINTS], after[7 * MAX_POINTS];
    int grabbed = 0;
    if (!ok(chaintube_rig_clip_info(rig, c->hose, c->carriage_clip, &clip), "clip info")) return 0;
    for (int32_t point = home_segment; point <= home_segment + 1; ++point) {
        chaintube_hose_result result;
        double moved = 0.0;
        if (point == clip.segment || point == clip.segment + 1) continue;
        if (!ok(chaintube_rig_joint_poses_f64(rig, c->hose, NULL, 0, before, 7 * MAX_POINTS),
                "joint poses") ||
            !ok(chaintube_rig_grab(rig, c->hose, point, &before[7 * point], &result),
                "chaintube_rig_grab of a point the clip let go of") ||
            !ok(chaintube_rig_update(rig, NULL), "chaintube_rig_update") ||
            !ok(chaintube_rig_joint_poses_f64(rig, c->hose, NULL, 0, after, 7 * MAX_POINTS),
                "joint poses"))
            continue;
        CHECK(result.status == CHAINTUBE_HOSE_OK, "the grab of point %d: status %d", (int)point,
              (int)result.status);
        for (int32_t k = 0; k < c->points; ++k) {
            const double d = distance(&before[7 * k], &after[7 * k]);
            if (d > moved) moved = d;
        }
        CHECK(moved <= TOLERANCE, "the grab of point %d where it is moved a point %.3g m",
              (int)point, moved);
        ok(chaintube_rig_release(rig, c->hose), "chaintube_rig_release");
        ++grabbed;
    }
    return grabbed;
}

int main(int argc, char** argv)
{
    chaintube_rig* rig = NULL;
    cable c;
    int32_t carriage = -1, plate = -1, other = -1;
    double trs[10], home[10], centre[3], home_centre[3];
    double slide_home, slide_max = -1.0, slide_min = 1e9;
    int frames = 0;
    int32_t home_segment = -1;
    if (argc != 2) {
        fprintf(stderr, "usage: capi_clip_test <motion-rig.glb>\n");
        return 2;
    }
    memset(&c, 0, sizeof c);
    if (!ok(chaintube_rig_load_file(CHAINTUBE_RUNTIME_ABI_VERSION, argv[1], &rig),
            "chaintube_rig_load_file"))
        return 1;
    if (ok(chaintube_rig_find_hose(rig, "carriage-cable", &c.hose), "find carriage-cable") &&
        ok(chaintube_rig_find_hose(rig, "carriage-feed", &other), "find carriage-feed") &&
        ok(chaintube_rig_find_node(rig, "carriage", &carriage), "find carriage") &&
        ok(chaintube_rig_find_node(rig, "base_plate", &plate), "find base_plate") &&
        ok(chaintube_rig_clip_count(rig, c.hose, &c.clips), "chaintube_rig_clip_count")) {
        chaintube_hose_info info;
        CHECK(c.clips == 2, "carriage-cable has %d clips, expected 2", (int)c.clips);
        ok(chaintube_rig_hose_info(rig, c.hose, &info), "chaintube_rig_hose_info");
        c.points = info.point_count;
        c.rest_length = info.rest_length;
        CHECK(c.points == 25 && c.points <= MAX_POINTS, "%d points", (int)c.points);
        ok(chaintube_rig_rest_lengths(rig, c.hose, c.rest, MAX_POINTS, &c.band),
           "chaintube_rig_rest_lengths");
        CHECK(c.band == 0.02, "band %g, expected the cable bundle's 0.02", c.band);
        for (int s = 0; s + 1 < c.points; ++s)
            c.prefix[s + 1] = c.prefix[s] + c.rest[s];
        CHECK(fabs(c.prefix[c.points - 1] - c.rest_length) <= TOLERANCE,
              "the rest lengths sum to %.17g, rest_length %.17g", c.prefix[c.points - 1],
              c.rest_length);
        c.carriage_clip = -1;
        for (int32_t k = 0; k < c.clips && k < MAX_CLIPS; ++k) {
            chaintube_clip_info clip;
            if (!ok(chaintube_rig_clip_info(rig, c.hose, k, &clip), "chaintube_rig_clip_info"))
                continue;
            CHECK(clip.turning == 0, "clip %d is sliding-turning", (int)k);
            CHECK(clip.slide_min == 0.0 && fabs(clip.slide_max - c.rest_length) <= TOLERANCE,
                  "clip %d end stops %g ... %g: expected the hose's ends", (int)k, clip.slide_min,
                  clip.slide_max);
            if (clip.node == carriage) c.carriage_clip = k, home_segment = clip.segment;
            if (k == 0) CHECK(clip.node == carriage, "clip 0 on node %d", (int)clip.node);
            if (k == 1) CHECK(clip.node == plate, "clip 1 on node %d", (int)clip.node);
        }
    }
    if (failures > 0 || c.carriage_clip < 0) {
        fprintf(stderr, "capi_clip_test: %s: the rig is not the motion-rig sample's\n", argv[1]);
        chaintube_rig_destroy(rig);
        return 1;
    }

    slide_home = check_cable(rig, &c, "as loaded", home_centre);
    CHECK(fabs(slide_home - 0.3) <= TOLERANCE, "the carriage clip's place %.17g, exported 0.3",
          slide_home);
    ok(chaintube_rig_node_transform(rig, carriage, home), "chaintube_rig_node_transform");
    memcpy(trs, home, sizeof trs);
    /* Out to +50 mm, back to -50 mm, home: 5 mm a frame. */
    for (int step = 1; step <= 40; ++step) {
        const int millimetres = step <= 10   ? 5 * step
                                : step <= 30 ? 100 - 5 * step
                                             : 5 * step - 200;
        char when[64];
        double slide;
        trs[0] = home[0] + 0.001 * millimetres;
        snprintf(when, sizeof when, "frame %d, carriage at %+d mm", step, millimetres);
        if (!ok(chaintube_rig_set_node_transform(rig, carriage, trs), "set_node_transform") ||
            !ok(chaintube_rig_update(rig, NULL), "chaintube_rig_update"))
            break;
        ++frames;
        slide = check_cable(rig, &c, when, centre);
        /* The clip goes with the carriage (the sample's parents are identity transforms). */
        CHECK(fabs(centre[0] - (home_centre[0] + 0.001 * millimetres)) <= TOLERANCE &&
                  fabs(centre[1] - home_centre[1]) <= TOLERANCE &&
                  fabs(centre[2] - home_centre[2]) <= TOLERANCE,
              "%s: the clip's centre (%.12g, %.12g, %.12g)", when, centre[0], centre[1], centre[2]);
        if (slide > slide_max) slide_max = slide;
        if (slide < slide_min) slide_min = slide;
        if (millimetres == 50) {
            CHECK(slide - slide_home >= 0.04, "%s: slid %.4g m through the clip, expected 0.04+",
                  when, slide - slide_home);
            CHECK(check_held_points_refuse_grabs(rig, &c) > 0,
                  "%s: the clip holds no grabbable point", when);
            CHECK(check_released_points_grab(rig, &c, home_segment) > 0,
                  "%s: the clip still holds both points it held as loaded", when);
        }
        if (millimetres == -50)
            CHECK(slide_home - slide >= 0.04,
                  "%s: slid %.4g m back through the clip, expected 0.04+", when,
                  slide_home - slide);
    }
    CHECK(frames == 40, "%d frames of 40", frames);
    check_refusals(rig, &c, other);
    chaintube_rig_destroy(rig);
    printf("capi_clip_test: %s: carriage-cable through %d clips over %d frames of the carriage "
           "(+-50 mm): the carriage clip's slide %.4f ... %.4f m (exported %.4f), %ld checks, "
           "%d failures\n",
           argv[1], (int)c.clips, frames, slide_min, slide_max, slide_home, checks, failures);
    return failures == 0 ? 0 : 1;
}
