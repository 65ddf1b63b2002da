/* The C ABI gives the C++ runtime's figures: replays the inputs of a reference file written by
 * capi_reference (the C++ runtime on the same export) through chaintube/runtime_c.h, once on
 * the rig loaded from the file and once on the rig loaded from its bytes in memory (moves,
 * grabs, a hose reeled out and back in: chaintube_rig_reel and its result), and
 * compares every hose's properties, frame results, joint poses (1e-9 m and 1e-9 in each
 * quaternion component) and surface with the reference.
 *
 *   capi_replay_test <export.glb> <reference.txt>
 *
 * Compiled as C99. Exit 0: every figure agrees; 1: a difference (each printed); 77: the export
 * is absent (skipped, e.g. the engine sample without ../shared/scenes). */
#include "chaintube/runtime_c.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define TOLERANCE 1e-9
/* The axial stiffness (EA, N per unit strain) capi_reference writes the pulls' forces for. */
#define PULL_STIFFNESS 1e4

static int failures = 0;
static long compared = 0;
static double largest_difference = 0.0;

static void fail_at(const char* where, int line, const char* what)
{
    fprintf(stderr, "FAIL %s, reference line %d: %s\n", where, line, what);
    ++failures;
}

/* A call that must succeed. */
static int call_ok(chaintube_status status, const char* where, int line, const char* call)
{
    char text[1024];
    if (status == CHAINTUBE_OK) return 1;
    snprintf(text, sizeof text, "%s returned %s: %s", call, chaintube_status_name(status),
             chaintube_last_error());
    fail_at(where, line, text);
    return 0;
}

static void expect_near(double actual, double expected, const char* where, int line,
                        const char* what)
{
    const double difference = fabs(actual - expected);
    char text[256];
    ++compared;
    if (difference > largest_difference) largest_difference = difference;
    if (!(difference <= TOLERANCE)) {
        snprintf(text, sizeof text, "%s: C ABI %.17g, C++ runtime %.17g", what, actual, expected);
        fail_at(where, line, text);
    }
}

static void expect_int(long actual, long expected, const char* where, int line, const char* what)
{
    char text[256];
    ++compared;
    if (actual != expected) {
        snprintf(text, sizeof text, "%s: C ABI %ld, C++ runtime %ld", what, actual, expected);
        fail_at(where, line, text);
    }
}

/* Floats computed the same way are the same bits. */
static void expect_same_float(float actual, float expected, const char* where, int line,
                              const char* what)
{
    char text[256];
    ++compared;
    if (actual != expected) {
        snprintf(text, sizeof text, "%s: %.9g, expected %.9g (the same float)", what, actual,
                 expected);
        fail_at(where, line, text);
    }
}

/* Reads up to `count` numbers from text into values; returns how many were read. */
static int read_numbers(const char* text, double* values, int count)
{
    int n = 0;
    char* end = NULL;
    while (n < count) {
        const double value = strtod(text, &end);
        if (end == text) break;
        values[n++] = value;
        text = end;
    }
    return n;
}

/* The text after `skip` space-separated words, without the line break. */
static const char* rest_after(char* line, int skip)
{
    char* at = line;
    for (int k = 0; k < skip; ++k) {
        at = strchr(at, ' ');
        if (!at) return "";
        ++at;
    }
    at[strcspn(at, "\r\n")] = '\0';
    return at;
}

/* Joint poses and surface of one hose, fetched once after each change. */
typedef struct
{
    int hose; /* -1: nothing fetched since the last change */
    int joints, vertices, indices;
    double* local;
    double* world;
    float* local_f;
    float* world_f;
    int32_t* nodes;
    float* positions;
    float* normals;
    uint32_t* index_data;
    float* uvs;
} hose_state;

static void forget(hose_state* state)
{
    free(state->local);
    free(state->world);
    free(state->local_f);
    free(state->world_f);
    free(state->nodes);
    free(state->positions);
    free(state->normals);
    free(state->index_data);
    free(state->uvs);
    memset(state, 0, sizeof *state);
    state->hose = -1;
}

static int fetch(const chaintube_rig* rig, int hose, hose_state* state, const char* where, int line)
{
    chaintube_hose_info info;
    if (state->hose == hose) return 1;
    forget(state);
    if (!call_ok(chaintube_rig_hose_info(rig, hose, &info), where, line, "chaintube_rig_hose_info"))
        return 0;
    state->hose = hose;
    state->joints = info.joint_count;
    state->vertices = info.vertex_count;
    state->indices = info.index_count;
    /* +1: never a zero-size allocation */
    state->local = malloc(sizeof(double) * (10 * (size_t)info.joint_count + 1));
    state->world = malloc(sizeof(double) * (7 * (size_t)info.joint_count + 1));
    state->local_f = malloc(sizeof(float) * (10 * (size_t)info.joint_count + 1));
    state->world_f = malloc(sizeof(float) * (7 * (size_t)info.joint_count + 1));
    state->nodes = malloc(sizeof(int32_t) * ((size_t)info.joint_count + 1));
    state->positions = malloc(sizeof(float) * (3 * (size_t)info.vertex_count + 1));
    state->normals = malloc(sizeof(float) * (3 * (size_t)info.vertex_count + 1));
    state->index_data = malloc(sizeof(uint32_t) * ((size_t)info.index_count + 1));
    state->uvs = malloc(sizeof(float) * (2 * (size_t)info.vertex_count + 1));
    if (!state->local || !state->world || !state->local_f || !state->world_f || !state->nodes ||
        !state->positions || !state->normals || !state->index_data || !state->uvs) {
        fail_at(where, line, "out of memory");
        return 0;
    }
    return call_ok(chaintube_rig_joint_poses_f64(rig, hose, state->local, 10 * info.joint_count,
                                                 state->world, 7 * info.joint_count),
                   where, line, "chaintube_rig_joint_poses_f64") &&
           call_ok(chaintube_rig_joint_poses(rig, hose, state->local_f, 10 * info.joint_count,
                                             state->world_f, 7 * info.joint_count),
                   where, line, "chaintube_rig_joint_poses") &&
           call_ok(chaintube_rig_joint_nodes(rig, hose, state->nodes, info.joint_count), where,
                   line, "chaintube_rig_joint_nodes") &&
           call_ok(chaintube_rig_surface(rig, hose, state->positions, 3 * info.vertex_count,
                                         state->normals, 3 * info.vertex_count),
                   where, line, "chaintube_rig_surface") &&
           call_ok(chaintube_rig_surface_topology(rig, hose, state->index_data, info.index_count,
                                                  state->uvs, 2 * info.vertex_count),
                   where, line, "chaintube_rig_surface_topology");
}

static void compare_result(const chaintube_hose_result* r, const double* expected,
                           const char* where, int line)
{
    expect_int(r->status, (long)expected[0], where, line, "status");
    expect_int(r->blocked, (long)expected[1], where, line, "blocked");
    expect_int(r->moved_points, (long)expected[2], where, line, "moved points");
    expect_int(r->contacts, (long)expected[3], where, line, "contacts");
    expect_near(r->length_violation, expected[4], where, line, "length violation");
    expect_near(r->angle_violation, expected[5], where, line, "angle violation");
    expect_near(r->grab_error, expected[6], where, line, "grab error");
    expect_near(r->penetration, expected[7], where, line, "penetration");
}

/* Replays the reference's inputs on `rig` and compares every figure; `where` names the run. */
static void replay(chaintube_rig* rig, const char* reference, const char* where)
{
    static char line[8192];
    double v[32];
    char word[32];
    int line_number = 0;
    chaintube_hose_result grab_result;
    chaintube_reel_result reel_result;
    hose_state state;
    FILE* file = fopen(reference, "r");
    memset(&state, 0, sizeof state);
    memset(&reel_result, 0, sizeof reel_result);
    state.hose = -1;
    if (!file) {
        fail_at(where, 0, "the reference file cannot be read");
        return;
    }
    while (fgets(line, sizeof line, file)) {
        const char* numbers;
        ++line_number;
        if (sscanf(line, "%31s", word) != 1) continue;
        numbers = line + strlen(word);
        if (strcmp(word, "rig") == 0) {
            int32_t hoses = 0, nodes = 0;
            read_numbers(numbers, v, 2);
            if (call_ok(chaintube_rig_hose_count(rig, &hoses), where, line_number, "hose_count") &&
                call_ok(chaintube_rig_node_count(rig, &nodes), where, line_number, "node_count")) {
                expect_int(hoses, (long)v[0], where, line_number, "hose count");
                expect_int(nodes, (long)v[1], where, line_number, "node count");
            }
        } else if (strcmp(word, "hose") == 0) {
            chaintube_hose_info info;
            int32_t found = -1;
            const char* id;
            read_numbers(numbers, v, 9);
            id = rest_after(line, 10);
            if (!call_ok(chaintube_rig_hose_info(rig, (int32_t)v[0], &info), where, line_number,
                         "hose_info"))
                continue;
            expect_int(info.point_count, (long)v[1], where, line_number, "point count");
            expect_int(info.joint_count, (long)v[2], where, line_number, "joint count");
            expect_int(info.grabbable_count, (long)v[3], where, line_number, "grabbable count");
            expect_int(info.vertex_count, (long)v[4], where, line_number, "vertex count");
            expect_int(info.index_count, (long)v[5], where, line_number, "index count");
            expect_int(info.is_static, (long)v[6], where, line_number, "static");
            expect_near(info.rest_length, v[7], where, line_number, "rest length");
            expect_near(info.outer_radius, v[8], where, line_number, "outer radius");
            expect_int(strcmp(info.id, id), 0, where, line_number, "id (strcmp)");
            if (call_ok(chaintube_rig_find_hose(rig, id, &found), where, line_number, "find_hose"))
                expect_int(found, (long)v[0], where, line_number, "find_hose(id)");
        } else if (strcmp(word, "node-name") == 0) {
            chaintube_node_info info;
            int32_t found = -1;
            const char* name;
            read_numbers(numbers, v, 1);
            name = rest_after(line, 2);
            if (call_ok(chaintube_rig_find_node(rig, name, &found), where, line_number,
                        "find_node"))
                expect_int(found, (long)v[0], where, line_number, "find_node(name)");
            if (call_ok(chaintube_rig_node_info(rig, (int32_t)v[0], &info), where, line_number,
                        "node_info"))
                expect_int(strcmp(info.name, name), 0, where, line_number, "node name (strcmp)");
        } else if (strcmp(word, "move") == 0) {
            double trs[10], readBack[10];
            read_numbers(numbers, v, 11);
            memcpy(trs, v + 1, sizeof trs);
            state.hose = -1;
            if (call_ok(chaintube_rig_set_node_transform(rig, (int32_t)v[0], trs), where,
                        line_number, "set_node_transform") &&
                call_ok(chaintube_rig_node_transform(rig, (int32_t)v[0], readBack), where,
                        line_number, "node_transform"))
                for (int k = 0; k < 10; ++k) /* the rotation comes back normalised */
                    expect_near(readBack[k], trs[k], where, line_number,
                                "node transform read back");
        } else if (strcmp(word, "grab") == 0) {
            read_numbers(numbers, v, 5);
            state.hose = -1;
            call_ok(chaintube_rig_grab(rig, (int32_t)v[0], (int32_t)v[1], v + 2, &grab_result),
                    where, line_number, "grab");
        } else if (strcmp(word, "grab-result") == 0) {
            read_numbers(numbers, v, 8);
            compare_result(&grab_result, v, where, line_number);
        } else if (strcmp(word, "reel") == 0) {
            read_numbers(numbers, v, 6);
            state.hose = -1;
            call_ok(chaintube_rig_reel(rig, (int32_t)v[0], (int32_t)v[1], (int32_t)v[2], v[3], v[4],
                                       v[5], &reel_result),
                    where, line_number, "reel");
        } else if (strcmp(word, "reel-result") == 0) {
            read_numbers(numbers, v, 7);
            expect_near(reel_result.paid, v[0], where, line_number, "reel paid");
            expect_near(reel_result.rest_length, v[1], where, line_number, "reel rest length");
            expect_near(reel_result.largest_move, v[2], where, line_number, "reel largest move");
            expect_int(reel_result.clamped, (long)v[3], where, line_number, "reel clamped");
            expect_int(reel_result.segments_added, (long)v[4], where, line_number, "reel added");
            expect_int(reel_result.segments_removed, (long)v[5], where, line_number,
                       "reel removed");
            expect_int(reel_result.point_count, (long)v[6], where, line_number, "reel points");
        } else if (strcmp(word, "release") == 0) {
            read_numbers(numbers, v, 1);
            state.hose = -1;
            call_ok(chaintube_rig_release(rig, (int32_t)v[0]), where, line_number, "release");
        } else if (strcmp(word, "update") == 0) {
            state.hose = -1;
            call_ok(chaintube_rig_update(rig, NULL), where, line_number, "update");
        } else if (strcmp(word, "result") == 0) {
            chaintube_hose_result result;
            read_numbers(numbers, v, 9);
            if (call_ok(chaintube_rig_hose_result(rig, (int32_t)v[0], &result), where, line_number,
                        "hose_result"))
                compare_result(&result, v + 1, where, line_number);
        } else if (strcmp(word, "pose") == 0) {
            int joint;
            read_numbers(numbers, v, 20);
            joint = (int)v[1];
            if (!fetch(rig, (int)v[0], &state, where, line_number)) continue;
            if (joint >= state.joints) {
                fail_at(where, line_number, "the C ABI has fewer joints than the reference");
                continue;
            }
            expect_int(state.nodes[joint], (long)v[2], where, line_number, "joint node");
            for (int k = 0; k < 10; ++k) {
                expect_near(state.local[10 * joint + k], v[3 + k], where, line_number,
                            k < 3   ? "local translation"
                            : k < 7 ? "local rotation"
                                    : "local scale");
                expect_same_float(state.local_f[10 * joint + k], (float)state.local[10 * joint + k],
                                  where, line_number, "float local pose vs the double one rounded");
            }
            for (int k = 0; k < 7; ++k) {
                expect_near(state.world[7 * joint + k], v[13 + k], where, line_number,
                            k < 3 ? "world translation" : "world rotation");
                expect_same_float(state.world_f[7 * joint + k], (float)state.world[7 * joint + k],
                                  where, line_number, "float world pose vs the double one rounded");
            }
        } else if (strcmp(word, "surface") == 0) {
            double positions = 0.0, normals = 0.0, indices = 0.0, uvs = 0.0;
            read_numbers(numbers, v, 6);
            if (!fetch(rig, (int)v[0], &state, where, line_number)) continue;
            expect_int(state.vertices, (long)v[1], where, line_number, "vertex count");
            for (int k = 0; k < 3 * state.vertices; ++k) {
                positions += state.positions[k];
                normals += state.normals[k];
            }
            for (int k = 0; k < state.indices; ++k)
                indices += state.index_data[k];
            for (int k = 0; k < 2 * state.vertices; ++k)
                uvs += state.uvs[k];
            expect_near(positions, v[2], where, line_number, "sum of surface positions");
            expect_near(normals, v[3], where, line_number, "sum of surface normals");
            expect_near(indices, v[4], where, line_number, "sum of surface indices");
            expect_near(uvs, v[5], where, line_number, "sum of surface uvs");
        } else if (strcmp(word, "vertex") == 0) {
            int vertex;
            read_numbers(numbers, v, 8);
            vertex = (int)v[1];
            if (!fetch(rig, (int)v[0], &state, where, line_number)) continue;
            if (vertex >= state.vertices) {
                fail_at(where, line_number, "the C ABI has fewer vertices than the reference");
                continue;
            }
            for (int k = 0; k < 3; ++k) {
                /* %.9g reads back as the same float: the same computation gives the same bits */
                expect_same_float(state.positions[3 * vertex + k], (float)v[2 + k], where,
                                  line_number, "surface position");
                expect_same_float(state.normals[3 * vertex + k], (float)v[5 + k], where,
                                  line_number, "surface normal");
            }
        } else if (strcmp(word, "attachments") == 0) {
            int32_t count = -1;
            read_numbers(numbers, v, 2);
            if (call_ok(chaintube_rig_attachment_count(rig, (int32_t)v[0], &count), where,
                        line_number, "attachment_count"))
                expect_int(count, (long)v[1], where, line_number, "attachment count");
        } else if (strcmp(word, "pull") == 0) {
            chaintube_attachment_pull pull;
            read_numbers(numbers, v, 13);
            if (!call_ok(chaintube_rig_attachment_pull(rig, (int32_t)v[0], (int32_t)v[1],
                                                       PULL_STIFFNESS, &pull),
                         where, line_number, "attachment_pull"))
                continue;
            expect_int(pull.node, (long)v[2], where, line_number, "attachment node");
            expect_int(pull.first_point, (long)v[3], where, line_number, "attachment first point");
            expect_int(pull.last_point, (long)v[4], where, line_number, "attachment last point");
            expect_near(pull.tautness, v[5], where, line_number, "tautness");
            expect_near(pull.strain, v[6], where, line_number, "strain");
            for (int k = 0; k < 3; ++k) {
                expect_near(pull.direction[k], v[7 + k], where, line_number, "pull direction");
                /* newtons: the same relative tolerance as metres at 1 m */
                expect_near(pull.force[k] / PULL_STIFFNESS, v[10 + k] / PULL_STIFFNESS, where,
                            line_number, "pull force / EA");
            }
        } else if (strcmp(word, "socket") == 0) {
            chaintube_socket_info info;
            int32_t found = -1;
            const char* id;
            read_numbers(numbers, v, 11);
            id = rest_after(line, 12);
            if (!call_ok(chaintube_rig_socket_info(rig, (int32_t)v[0], &info), where, line_number,
                         "socket_info"))
                continue;
            expect_int(info.node, (long)v[1], where, line_number, "socket node");
            expect_int(info.occupant_hose, (long)v[2], where, line_number, "socket occupant hose");
            expect_int(info.occupant_end, (long)v[3], where, line_number, "socket occupant end");
            expect_int(info.occupant_attachment, (long)v[4], where, line_number,
                       "socket occupant attachment");
            for (int k = 0; k < 3; ++k) {
                expect_near(info.position[k], v[5 + k], where, line_number, "socket position");
                expect_near(info.axis[k], v[8 + k], where, line_number, "socket axis");
            }
            expect_int(strcmp(info.id, id), 0, where, line_number, "socket id (strcmp)");
            if (call_ok(chaintube_rig_find_socket(rig, id, &found), where, line_number,
                        "find_socket"))
                expect_int(found, (long)v[0], where, line_number, "find_socket(id)");
        } else if (strcmp(word, "unplug") == 0) {
            int32_t left = -2;
            read_numbers(numbers, v, 3);
            state.hose = -1;
            if (call_ok(chaintube_rig_unplug(rig, (int32_t)v[0], (int32_t)v[1], &left), where,
                        line_number, "unplug"))
                expect_int(left, (long)v[2], where, line_number, "the socket unplugged from");
        } else if (strcmp(word, "plug") == 0) {
            int32_t attachment = -2;
            read_numbers(numbers, v, 4);
            state.hose = -1;
            if (call_ok(chaintube_rig_plug(rig, (int32_t)v[0], (int32_t)v[1], (int32_t)v[2],
                                           &attachment),
                        where, line_number, "plug"))
                expect_int(attachment, (long)v[3], where, line_number, "the plug's attachment");
        } else if (strcmp(word, "release-snap") == 0) {
            int32_t socket = -2;
            read_numbers(numbers, v, 2);
            state.hose = -1;
            if (call_ok(chaintube_rig_release_snap(rig, (int32_t)v[0], &socket), where, line_number,
                        "release_snap"))
                expect_int(socket, (long)v[1], where, line_number, "the socket snapped into");
        } else {
            fail_at(where, line_number, "unknown reference line");
        }
    }
    forget(&state);
    fclose(file);
}

static char* read_file(const char* path, size_t* size)
{
    FILE* file = fopen(path, "rb");
    char* bytes = NULL;
    long length;
    if (!file) return NULL;
    if (fseek(file, 0, SEEK_END) == 0 && (length = ftell(file)) >= 0 &&
        fseek(file, 0, SEEK_SET) == 0 && (bytes = malloc((size_t)length + 1)) != NULL) {
        *size = fread(bytes, 1, (size_t)length, file);
        if (*size != (size_t)length) {
            free(bytes);
            bytes = NULL;
        }
    }
    fclose(file);
    return bytes;
}

int main(int argc, char** argv)
{
    chaintube_rig* rig = NULL;
    char* bytes;
    size_t size = 0;
    const char* name;
    if (argc != 3) {
        fprintf(stderr, "usage: capi_replay_test <export.glb> <reference.txt>\n");
        return 2;
    }
    bytes = read_file(argv[1], &size);
    if (!bytes) {
        printf("skipped: %s is absent (the engine samples need ../shared/scenes)\n", argv[1]);
        return 77;
    }
    name = strrchr(argv[1], '/') ? strrchr(argv[1], '/') + 1 : argv[1];

    if (call_ok(chaintube_rig_load_file(CHAINTUBE_RUNTIME_ABI_VERSION, argv[1], &rig), "file", 0,
                "chaintube_rig_load_file")) {
        replay(rig, argv[2], "loaded from the file");
        chaintube_rig_destroy(rig);
    }
    rig = NULL;
    if (call_ok(chaintube_rig_load_memory(CHAINTUBE_RUNTIME_ABI_VERSION, name, bytes, size, NULL, 0,
                                          NULL, 0, &rig),
                "memory", 0, "chaintube_rig_load_memory")) {
        memset(bytes, 0, size); /* the rig keeps its own copy */
        replay(rig, argv[2], "loaded from memory");
        chaintube_rig_destroy(rig);
    }
    free(bytes);
    printf("capi_replay_test: %s, loaded from the file and from memory: %ld figures compared "
           "with the C++ runtime, largest difference %.3g (tolerance %g), %d failures\n",
           argv[1], compared, largest_difference, TOLERANCE, failures);
    return failures == 0 && compared > 0 ? 0 : 1;
}
