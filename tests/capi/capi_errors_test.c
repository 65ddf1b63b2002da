/* The C ABI refuses bad input with a status and a message, and changes nothing: null handles
 * and pointers, short buffers, indices out of range, NaN/Inf inputs, points that are not
 * grabbable, a caller built against another ABI version, unreadable files, malformed GLB bytes
 * and glTF JSON, a missing buffer or descriptor.
 *
 *   capi_errors_test <test-rig.glb> <rig-options-split.gltf> <scratch folder>
 *
 * Compiled as C99. Exit 0 when every case behaves; each failing case is printed. */
#include "chaintube/runtime_c.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int failures = 0;
static int cases = 0;

#define CHECK(condition, ...)                                                                      \
    do {                                                                                           \
        ++cases;                                                                                   \
        if (!(condition)) {                                                                        \
            fprintf(stderr, "FAIL line %d: %s: ", __LINE__, #condition);                           \
            fprintf(stderr, __VA_ARGS__);                                                          \
            fprintf(stderr, "\n");                                                                 \
            ++failures;                                                                            \
        }                                                                                          \
    } while (0)

/* `status` is `expected` and the last error contains every one of the NULL-ended words. */
static void expect_error(int line, chaintube_status status, chaintube_status expected, ...)
{
    const char* message = chaintube_last_error();
    const char* word;
    va_list words;
    ++cases;
    if (status != expected) {
        fprintf(stderr, "FAIL line %d: returned %s, expected %s (last error: %s)\n", line,
                chaintube_status_name(status), chaintube_status_name(expected), message);
        ++failures;
        return;
    }
    va_start(words, expected);
    while ((word = va_arg(words, const char*)) != NULL)
        if (!strstr(message, word)) {
            fprintf(stderr, "FAIL line %d: the message does not name \"%s\": %s\n", line, word,
                    message);
            ++failures;
        }
    va_end(words);
}
#define EXPECT_ERROR(call, expected, ...)                                                          \
    expect_error(__LINE__, (call), (expected), __VA_ARGS__, NULL)

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

static void write_u32(char* at, uint32_t value)
{
    at[0] = (char)(value & 0xFF);
    at[1] = (char)((value >> 8) & 0xFF);
    at[2] = (char)((value >> 16) & 0xFF);
    at[3] = (char)((value >> 24) & 0xFF);
}

/* Everything a frame reads, to show that a refused call changed nothing. */
typedef struct
{
    double poses[2][7 * 256];
    float positions[2][3 * 8192];
    double node[10];
    chaintube_hose_result results[2];
} snapshot;

static void take(const chaintube_rig* rig, int32_t node, snapshot* s)
{
    memset(s, 0, sizeof *s);
    for (int32_t h = 0; h < 2; ++h) {
        CHECK(chaintube_rig_joint_poses_f64(rig, h, NULL, 0, s->poses[h], 7 * 256) == CHAINTUBE_OK,
              "%s", chaintube_last_error());
        CHECK(chaintube_rig_surface(rig, h, s->positions[h], 3 * 8192, NULL, 0) == CHAINTUBE_OK,
              "%s", chaintube_last_error());
        CHECK(chaintube_rig_hose_result(rig, h, &s->results[h]) == CHAINTUBE_OK, "%s",
              chaintube_last_error());
    }
    CHECK(chaintube_rig_node_transform(rig, node, s->node) == CHAINTUBE_OK, "%s",
          chaintube_last_error());
}

static void expect_unchanged(int line, const chaintube_rig* rig, int32_t node,
                             const snapshot* before)
{
    static snapshot after;
    take(rig, node, &after);
    ++cases;
    if (memcmp(before, &after, sizeof after) != 0) {
        fprintf(stderr, "FAIL line %d: a refused call changed the rig\n", line);
        ++failures;
    }
}

static void loading(const char* rig_file, const char* split_gltf, const char* scratch)
{
    chaintube_rig* const untouched = (chaintube_rig*)&failures; /* any non-NULL marker */
    chaintube_rig* rig = untouched;
    const uint32_t next_major = (uint32_t)(CHAINTUBE_RUNTIME_ABI_VERSION_MAJOR + 1) << 16;
    const uint32_t newer_minor = CHAINTUBE_RUNTIME_ABI_VERSION + 1;
    size_t size = 0, json_size = 0, bin_size = 0;
    char* bytes = read_file(rig_file, &size);
    char* json;
    char* bin;
    char path[4096];
    char bin_path[4096];
    chaintube_bytes buffer;
    FILE* file;
    const char* const plain = "{\"asset\": {\"version\": \"2.0\"}}";

    CHECK(bytes != NULL && size > 100, "%s cannot be read", rig_file);
    if (!bytes) return;
    CHECK(chaintube_runtime_abi_version() == CHAINTUBE_RUNTIME_ABI_VERSION, "0x%x",
          chaintube_runtime_abi_version());
    CHECK(strcmp(chaintube_last_error(), "") == 0, "before any failure: \"%s\"",
          chaintube_last_error());

    /* A caller built against another major version, or a newer minor, is refused. */
    EXPECT_ERROR(chaintube_rig_load_file(next_major, rig_file, &rig), CHAINTUBE_ERROR_ABI_MISMATCH,
                 "chaintube_rig_load_file", "ABI 2.0", "ABI 1.4");
    EXPECT_ERROR(
        chaintube_rig_load_memory(next_major, "rig.glb", bytes, size, NULL, 0, NULL, 0, &rig),
        CHAINTUBE_ERROR_ABI_MISMATCH, "chaintube_rig_load_memory", "ABI 2.0");
    EXPECT_ERROR(chaintube_rig_load_file(newer_minor, rig_file, &rig), CHAINTUBE_ERROR_ABI_MISMATCH,
                 "ABI 1.4", "minor");
    CHECK(rig == untouched, "a refused load wrote the rig");
    /* A caller built against an older minor version (1.0 ... 1.3) still loads. */
    for (uint32_t minor = 0; minor < CHAINTUBE_RUNTIME_ABI_VERSION_MINOR; ++minor) {
        chaintube_rig* older = NULL;
        const uint32_t version = ((uint32_t)CHAINTUBE_RUNTIME_ABI_VERSION_MAJOR << 16) | minor;
        CHECK(chaintube_rig_load_file(version, rig_file, &older) == CHAINTUBE_OK && older != NULL,
              "a caller of ABI 1.%u was refused: %s", (unsigned)minor, chaintube_last_error());
        CHECK(chaintube_rig_destroy(older) == CHAINTUBE_OK, "%s", chaintube_last_error());
    }

    /* Null pointers. */
    EXPECT_ERROR(chaintube_rig_load_file(CHAINTUBE_RUNTIME_ABI_VERSION, NULL, &rig),
                 CHAINTUBE_ERROR_INVALID_ARGUMENT, "path is NULL");
    EXPECT_ERROR(chaintube_rig_load_file(CHAINTUBE_RUNTIME_ABI_VERSION, rig_file, NULL),
                 CHAINTUBE_ERROR_INVALID_ARGUMENT, "rig is NULL");
    EXPECT_ERROR(chaintube_rig_load_memory(CHAINTUBE_RUNTIME_ABI_VERSION, "x.glb", NULL, 10, NULL,
                                           0, NULL, 0, &rig),
                 CHAINTUBE_ERROR_INVALID_ARGUMENT, "gltf is NULL");
    EXPECT_ERROR(chaintube_rig_load_memory(CHAINTUBE_RUNTIME_ABI_VERSION, "x.glb", bytes, size,
                                           NULL, 2, NULL, 0, &rig),
                 CHAINTUBE_ERROR_INVALID_ARGUMENT, "buffers is NULL");
    EXPECT_ERROR(chaintube_rig_load_memory(CHAINTUBE_RUNTIME_ABI_VERSION, "x.glb", bytes, size,
                                           NULL, -1, NULL, 0, &rig),
                 CHAINTUBE_ERROR_INVALID_ARGUMENT, "buffer_count is -1");
    CHECK(rig == untouched, "a refused load wrote the rig");

    /* An unreadable file: named, with its own status. */
    EXPECT_ERROR(
        chaintube_rig_load_file(CHAINTUBE_RUNTIME_ABI_VERSION, "/nonexistent/folder/rig.glb", &rig),
        CHAINTUBE_ERROR_UNREADABLE_FILE, "/nonexistent/folder/rig.glb", "cannot be read");

    /* Malformed GLB bytes, in memory and in a file: named, saying what was expected. */
    EXPECT_ERROR(chaintube_rig_load_memory(CHAINTUBE_RUNTIME_ABI_VERSION, "short.glb", bytes, 12,
                                           NULL, 0, NULL, 0, &rig),
                 CHAINTUBE_ERROR_MALFORMED, "short.glb", "truncated GLB header");
    write_u32(bytes + 4, 3); /* container version 3 */
    EXPECT_ERROR(chaintube_rig_load_memory(CHAINTUBE_RUNTIME_ABI_VERSION, "v3.glb", bytes, size,
                                           NULL, 0, NULL, 0, &rig),
                 CHAINTUBE_ERROR_MALFORMED, "v3.glb", "version 3, expected 2");
    write_u32(bytes + 4, 2);
    EXPECT_ERROR(chaintube_rig_load_memory(CHAINTUBE_RUNTIME_ABI_VERSION, "cut.glb", bytes,
                                           size - 1, NULL, 0, NULL, 0, &rig),
                 CHAINTUBE_ERROR_MALFORMED, "cut.glb", "header length");
    snprintf(path, sizeof path, "%s/truncated.glb", scratch);
    file = fopen(path, "wb");
    CHECK(file != NULL, "%s cannot be written", path);
    if (file) {
        fwrite(bytes, 1, size / 2, file);
        fclose(file);
        EXPECT_ERROR(chaintube_rig_load_file(CHAINTUBE_RUNTIME_ABI_VERSION, path, &rig),
                     CHAINTUBE_ERROR_MALFORMED, path, "GLB");
    }
    EXPECT_ERROR(chaintube_rig_load_memory(CHAINTUBE_RUNTIME_ABI_VERSION, "bad.gltf",
                                           "{\"nodes\": [", strlen("{\"nodes\": ["), NULL, 0, NULL,
                                           0, &rig),
                 CHAINTUBE_ERROR_MALFORMED, "bad.gltf", "malformed glTF JSON");
    EXPECT_ERROR(chaintube_rig_load_memory(CHAINTUBE_RUNTIME_ABI_VERSION, NULL, plain,
                                           strlen(plain), NULL, 0, NULL, 0, &rig),
                 CHAINTUBE_ERROR_MALFORMED, "<memory>", "CHAINTUBE_hose_rig",
                 "no sidecar descriptor");
    EXPECT_ERROR(chaintube_rig_load_memory(CHAINTUBE_RUNTIME_ABI_VERSION, "plain.gltf", plain,
                                           strlen(plain), NULL, 0, "{\"format\": 1}",
                                           strlen("{\"format\": 1}"), &rig),
                 CHAINTUBE_ERROR_MALFORMED, "plain.hoses.json", "/format");
    CHECK(rig == untouched, "a refused load wrote the rig");
    free(bytes);

    /* A .gltf with its .bin from memory: the buffer is needed for the collider meshes. */
    json = read_file(split_gltf, &json_size);
    snprintf(bin_path, sizeof bin_path, "%.*s.bin", (int)(strlen(split_gltf) - 5), split_gltf);
    bin = read_file(bin_path, &bin_size);
    CHECK(json && bin, "%s or %s cannot be read", split_gltf, bin_path);
    if (json && bin) {
        EXPECT_ERROR(chaintube_rig_load_memory(CHAINTUBE_RUNTIME_ABI_VERSION, "options.gltf", json,
                                               json_size, NULL, 0, NULL, 0, &rig),
                     CHAINTUBE_ERROR_MALFORMED, "options.gltf: /buffers/0", "was not given");
        buffer.data = NULL;
        buffer.size = 5;
        EXPECT_ERROR(chaintube_rig_load_memory(CHAINTUBE_RUNTIME_ABI_VERSION, "options.gltf", json,
                                               json_size, &buffer, 1, NULL, 0, &rig),
                     CHAINTUBE_ERROR_INVALID_ARGUMENT, "buffers[0].data is NULL");
        buffer.data = bin;
        buffer.size = bin_size / 2;
        EXPECT_ERROR(chaintube_rig_load_memory(CHAINTUBE_RUNTIME_ABI_VERSION, "options.gltf", json,
                                               json_size, &buffer, 1, NULL, 0, &rig),
                     CHAINTUBE_ERROR_MALFORMED, "options.gltf: /buffers/0/byteLength");
        CHECK(rig == untouched, "a refused load wrote the rig");
        buffer.size = bin_size;
        rig = NULL;
        CHECK(chaintube_rig_load_memory(CHAINTUBE_RUNTIME_ABI_VERSION, "options.gltf", json,
                                        json_size, &buffer, 1, NULL, 0, &rig) == CHAINTUBE_OK,
              "%s", chaintube_last_error());
        if (rig) {
            int32_t hoses = 0;
            CHECK(chaintube_rig_hose_count(rig, &hoses) == CHAINTUBE_OK && hoses > 0, "%d",
                  (int)hoses);
        }
        CHECK(chaintube_rig_destroy(rig) == CHAINTUBE_OK, "%s", chaintube_last_error());
    }
    free(json);
    free(bin);
}

static void null_handles(void)
{
    int32_t count = 7, index = 7, points[4], nodes[4];
    double trs[10] = {0, 0, 0, 0, 0, 0, 1, 1, 1, 1}, target[3] = {0, 0, 0}, poses64[32];
    float floats[64];
    uint32_t indices[16];
    const char* text = "untouched";
    chaintube_hose_info info;
    chaintube_node_info node;
    chaintube_hose_result result;
    chaintube_attachment_pull pull;
    EXPECT_ERROR(chaintube_rig_hose_count(NULL, &count), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                 "chaintube_rig_hose_count", "rig is NULL");
    EXPECT_ERROR(chaintube_rig_node_count(NULL, &count), CHAINTUBE_ERROR_INVALID_ARGUMENT, "rig");
    EXPECT_ERROR(chaintube_rig_warning_count(NULL, &count), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                 "rig");
    EXPECT_ERROR(chaintube_rig_warning(NULL, 0, &text), CHAINTUBE_ERROR_INVALID_ARGUMENT, "rig");
    EXPECT_ERROR(chaintube_rig_find_hose(NULL, "x", &index), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                 "rig");
    EXPECT_ERROR(chaintube_rig_find_node(NULL, "x", &index), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                 "rig");
    EXPECT_ERROR(chaintube_rig_hose_info(NULL, 0, &info), CHAINTUBE_ERROR_INVALID_ARGUMENT, "rig");
    EXPECT_ERROR(chaintube_rig_grabbable_points(NULL, 0, points, 4),
                 CHAINTUBE_ERROR_INVALID_ARGUMENT, "rig");
    EXPECT_ERROR(chaintube_rig_joint_nodes(NULL, 0, nodes, 4), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                 "rig");
    EXPECT_ERROR(chaintube_rig_node_info(NULL, 0, &node), CHAINTUBE_ERROR_INVALID_ARGUMENT, "rig");
    EXPECT_ERROR(chaintube_rig_node_transform(NULL, 0, trs), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                 "rig");
    EXPECT_ERROR(chaintube_rig_set_node_transform(NULL, 0, trs), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                 "chaintube_rig_set_node_transform", "rig is NULL");
    EXPECT_ERROR(chaintube_rig_grab(NULL, 0, 1, target, &result), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                 "chaintube_rig_grab", "rig is NULL");
    EXPECT_ERROR(chaintube_rig_release(NULL, 0), CHAINTUBE_ERROR_INVALID_ARGUMENT, "rig");
    EXPECT_ERROR(chaintube_rig_update(NULL, &count), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                 "chaintube_rig_update", "rig is NULL");
    EXPECT_ERROR(chaintube_rig_hose_result(NULL, 0, &result), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                 "rig");
    EXPECT_ERROR(chaintube_rig_joint_poses(NULL, 0, floats, 64, NULL, 0),
                 CHAINTUBE_ERROR_INVALID_ARGUMENT, "rig");
    EXPECT_ERROR(chaintube_rig_joint_poses_f64(NULL, 0, poses64, 32, NULL, 0),
                 CHAINTUBE_ERROR_INVALID_ARGUMENT, "rig");
    EXPECT_ERROR(chaintube_rig_surface(NULL, 0, floats, 64, NULL, 0),
                 CHAINTUBE_ERROR_INVALID_ARGUMENT, "rig");
    EXPECT_ERROR(chaintube_rig_surface_topology(NULL, 0, indices, 16, NULL, 0),
                 CHAINTUBE_ERROR_INVALID_ARGUMENT, "rig");
    EXPECT_ERROR(chaintube_rig_attachment_count(NULL, 0, &count), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                 "chaintube_rig_attachment_count", "rig is NULL");
    EXPECT_ERROR(chaintube_rig_attachment_pull(NULL, 0, 0, 1e4, &pull),
                 CHAINTUBE_ERROR_INVALID_ARGUMENT, "chaintube_rig_attachment_pull", "rig is NULL");
    CHECK(count == 7 && index == 7 && strcmp(text, "untouched") == 0,
          "a refused call wrote an output");
    CHECK(chaintube_rig_destroy(NULL) == CHAINTUBE_OK, "destroy(NULL) is a no-op");
}

static void per_frame(const char* rig_file)
{
    chaintube_rig* rig = NULL;
    chaintube_hose_info info;
    chaintube_hose_result result;
    chaintube_attachment_pull pull;
    static snapshot before;
    static float floats[3 * 8192];
    static double doubles[10 * 256];
    int32_t hoses = 0, nodes = 0, hose = -1, node = -1, index = 12345, point;
    int32_t grabbable[256], joint_nodes[256], warnings = -1;
    uint32_t indices[16];
    const char* text = "untouched";
    double trs[10], bad[10], target[3];
    const double not_a_number = nan("");

    if (!(chaintube_rig_load_file(CHAINTUBE_RUNTIME_ABI_VERSION, rig_file, &rig) == CHAINTUBE_OK)) {
        CHECK(0, "%s", chaintube_last_error());
        return;
    }
    CHECK(chaintube_rig_hose_count(rig, &hoses) == CHAINTUBE_OK && hoses == 2, "%d", (int)hoses);
    CHECK(chaintube_rig_node_count(rig, &nodes) == CHAINTUBE_OK && nodes > 0, "%d", (int)nodes);
    CHECK(chaintube_rig_warning_count(rig, &warnings) == CHAINTUBE_OK && warnings == 0, "%d",
          (int)warnings);
    CHECK(chaintube_rig_find_hose(rig, "left-feed", &hose) == CHAINTUBE_OK, "%s",
          chaintube_last_error());
    CHECK(chaintube_rig_hose_info(rig, hose, &info) == CHAINTUBE_OK && info.grabbable_count > 0 &&
              info.joint_count == info.point_count && info.joint_count <= 256,
          "%s", chaintube_last_error());
    CHECK(chaintube_rig_grabbable_points(rig, hose, grabbable, 256) == CHAINTUBE_OK, "%s",
          chaintube_last_error());
    CHECK(chaintube_rig_joint_nodes(rig, hose, joint_nodes, 256) == CHAINTUBE_OK, "%s",
          chaintube_last_error());
    node = joint_nodes[0];
    point = grabbable[info.grabbable_count / 2];
    CHECK(chaintube_rig_node_transform(rig, node, trs) == CHAINTUBE_OK, "%s",
          chaintube_last_error());
    take(rig, node, &before);

    /* Indices out of range. */
    EXPECT_ERROR(chaintube_rig_hose_info(rig, hoses, &info), CHAINTUBE_ERROR_OUT_OF_RANGE,
                 "hose 2 is out of range", "expected 0 to 1");
    EXPECT_ERROR(chaintube_rig_hose_info(rig, -1, &info), CHAINTUBE_ERROR_OUT_OF_RANGE, "hose -1");
    EXPECT_ERROR(chaintube_rig_node_info(rig, nodes, NULL), CHAINTUBE_ERROR_OUT_OF_RANGE, "node");
    EXPECT_ERROR(chaintube_rig_set_node_transform(rig, -1, trs), CHAINTUBE_ERROR_OUT_OF_RANGE,
                 "node -1 is out of range");
    EXPECT_ERROR(chaintube_rig_grab(rig, hoses, point, trs, NULL), CHAINTUBE_ERROR_OUT_OF_RANGE,
                 "hose 2");
    EXPECT_ERROR(chaintube_rig_grab(rig, hose, info.point_count, trs, NULL),
                 CHAINTUBE_ERROR_OUT_OF_RANGE, "point", "left-feed");
    EXPECT_ERROR(chaintube_rig_release(rig, 99), CHAINTUBE_ERROR_OUT_OF_RANGE, "hose 99");
    EXPECT_ERROR(chaintube_rig_warning(rig, 0, &text), CHAINTUBE_ERROR_OUT_OF_RANGE, "warning 0");
    EXPECT_ERROR(chaintube_rig_joint_poses(rig, -3, floats, 3 * 8192, NULL, 0),
                 CHAINTUBE_ERROR_OUT_OF_RANGE, "hose -3");
    EXPECT_ERROR(chaintube_rig_surface(rig, 5, floats, 3 * 8192, NULL, 0),
                 CHAINTUBE_ERROR_OUT_OF_RANGE, "hose 5");
    EXPECT_ERROR(chaintube_rig_hose_result(rig, 2, &result), CHAINTUBE_ERROR_OUT_OF_RANGE,
                 "hose 2");
    /* A point fixed by an attachment. */
    EXPECT_ERROR(chaintube_rig_grab(rig, hose, 0, trs, NULL), CHAINTUBE_ERROR_NOT_GRABBABLE,
                 "point 0", "not grabbable");
    /* Names that do not exist. */
    EXPECT_ERROR(chaintube_rig_find_hose(rig, "no-such-hose", &index), CHAINTUBE_ERROR_NOT_FOUND,
                 "no-such-hose");
    EXPECT_ERROR(chaintube_rig_find_node(rig, "no-such-node", &index), CHAINTUBE_ERROR_NOT_FOUND,
                 "no-such-node");
    EXPECT_ERROR(chaintube_rig_find_node(rig, NULL, &index), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                 "name is NULL");
    CHECK(index == 12345 && strcmp(text, "untouched") == 0, "a refused call wrote an output");

    /* NaN and Inf targets, degenerate transforms. */
    target[0] = 0.1;
    target[1] = not_a_number;
    target[2] = 0.0;
    EXPECT_ERROR(chaintube_rig_grab(rig, hose, point, target, &result),
                 CHAINTUBE_ERROR_INVALID_ARGUMENT, "target[1] is NaN", "finite");
    target[1] = 0.0;
    target[2] = -HUGE_VAL;
    EXPECT_ERROR(chaintube_rig_grab(rig, hose, point, target, &result),
                 CHAINTUBE_ERROR_INVALID_ARGUMENT, "target[2] is -Inf");
    EXPECT_ERROR(chaintube_rig_grab(rig, hose, point, NULL, &result),
                 CHAINTUBE_ERROR_INVALID_ARGUMENT, "target is NULL");
    memcpy(bad, trs, sizeof bad);
    bad[0] = not_a_number;
    EXPECT_ERROR(chaintube_rig_set_node_transform(rig, node, bad), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                 "trs[0] (translation x) is NaN");
    memcpy(bad, trs, sizeof bad);
    bad[5] = HUGE_VAL;
    EXPECT_ERROR(chaintube_rig_set_node_transform(rig, node, bad), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                 "trs[5] (rotation z) is +Inf");
    memcpy(bad, trs, sizeof bad);
    bad[3] = bad[4] = bad[5] = bad[6] = 0.0;
    EXPECT_ERROR(chaintube_rig_set_node_transform(rig, node, bad), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                 "rotation", "unit quaternion");
    memcpy(bad, trs, sizeof bad);
    bad[8] = 0.0;
    EXPECT_ERROR(chaintube_rig_set_node_transform(rig, node, bad), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                 "trs[8] (scale y) is 0");
    EXPECT_ERROR(chaintube_rig_set_node_transform(rig, node, NULL),
                 CHAINTUBE_ERROR_INVALID_ARGUMENT, "trs is NULL");

    /* Short buffers, and no buffer at all. */
    floats[0] = 42.0f;
    EXPECT_ERROR(chaintube_rig_joint_poses(rig, hose, floats, 10 * info.joint_count - 1, NULL, 0),
                 CHAINTUBE_ERROR_BUFFER_TOO_SMALL, "local has room for", "left-feed");
    EXPECT_ERROR(chaintube_rig_joint_poses(rig, hose, floats, 10 * info.joint_count, floats,
                                           7 * info.joint_count - 1),
                 CHAINTUBE_ERROR_BUFFER_TOO_SMALL, "world has room for");
    EXPECT_ERROR(chaintube_rig_joint_poses(rig, hose, NULL, 0, NULL, 0),
                 CHAINTUBE_ERROR_INVALID_ARGUMENT, "both NULL");
    EXPECT_ERROR(chaintube_rig_joint_poses_f64(rig, hose, doubles, -1, NULL, 0),
                 CHAINTUBE_ERROR_BUFFER_TOO_SMALL, "local has room for -1");
    EXPECT_ERROR(chaintube_rig_surface(rig, hose, floats, 3 * info.vertex_count - 1, NULL, 0),
                 CHAINTUBE_ERROR_BUFFER_TOO_SMALL, "positions has room for");
    EXPECT_ERROR(chaintube_rig_surface(rig, hose, NULL, 0, floats, 3),
                 CHAINTUBE_ERROR_BUFFER_TOO_SMALL, "normals has room for 3");
    EXPECT_ERROR(chaintube_rig_surface_topology(rig, hose, indices, 16, NULL, 0),
                 CHAINTUBE_ERROR_BUFFER_TOO_SMALL, "indices has room for 16");
    EXPECT_ERROR(chaintube_rig_grabbable_points(rig, hose, grabbable, 1),
                 CHAINTUBE_ERROR_BUFFER_TOO_SMALL, "points has room for 1");
    EXPECT_ERROR(chaintube_rig_joint_nodes(rig, hose, joint_nodes, 2),
                 CHAINTUBE_ERROR_BUFFER_TOO_SMALL, "nodes has room for 2");
    CHECK(floats[0] == 42.0f, "a refused call wrote the buffer");

    /* Attachment pulls: an attachment out of range, a bad axial stiffness, no output. */
    pull.tautness = 42.0;
    EXPECT_ERROR(chaintube_rig_attachment_count(rig, hoses, &index), CHAINTUBE_ERROR_OUT_OF_RANGE,
                 "chaintube_rig_attachment_count", "hose 2");
    EXPECT_ERROR(chaintube_rig_attachment_count(rig, hose, NULL), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                 "count is NULL");
    EXPECT_ERROR(chaintube_rig_attachment_pull(rig, hose, 2, 1e4, &pull),
                 CHAINTUBE_ERROR_OUT_OF_RANGE, "attachment 2 is out of range", "left-feed",
                 "has 2 attachments");
    EXPECT_ERROR(chaintube_rig_attachment_pull(rig, hose, -1, 1e4, &pull),
                 CHAINTUBE_ERROR_OUT_OF_RANGE, "attachment -1");
    EXPECT_ERROR(chaintube_rig_attachment_pull(rig, hose, 0, -1.0, &pull),
                 CHAINTUBE_ERROR_INVALID_ARGUMENT, "axial_stiffness", "expected a finite EA >= 0");
    EXPECT_ERROR(chaintube_rig_attachment_pull(rig, hose, 0, not_a_number, &pull),
                 CHAINTUBE_ERROR_INVALID_ARGUMENT, "axial_stiffness");
    EXPECT_ERROR(chaintube_rig_attachment_pull(rig, hose, 0, HUGE_VAL, &pull),
                 CHAINTUBE_ERROR_INVALID_ARGUMENT, "axial_stiffness");
    EXPECT_ERROR(chaintube_rig_attachment_pull(rig, hose, 0, 1e4, NULL),
                 CHAINTUBE_ERROR_INVALID_ARGUMENT, "pull is NULL");
    CHECK(pull.tautness == 42.0 && index == 12345, "a refused call wrote an output");

    /* Sockets: out of range, no such id, a tag that does not fit, an end that is not free. */
    {
        chaintube_socket_info socket_info;
        socket_info.occupant_hose = 42;
        EXPECT_ERROR(chaintube_rig_socket_count(NULL, &index), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                     "rig is NULL");
        EXPECT_ERROR(chaintube_rig_socket_count(rig, NULL), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                     "count is NULL");
        EXPECT_ERROR(chaintube_rig_find_socket(rig, "no-such-socket", &index),
                     CHAINTUBE_ERROR_NOT_FOUND, "no-such-socket", "2 sockets");
        EXPECT_ERROR(chaintube_rig_socket_info(rig, 2, &socket_info), CHAINTUBE_ERROR_OUT_OF_RANGE,
                     "socket 2 is out of range", "expected 0 to 1");
        EXPECT_ERROR(chaintube_rig_socket_info(rig, 0, NULL), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                     "info is NULL");
        EXPECT_ERROR(chaintube_rig_plug(rig, hose, 1, -1, &index), CHAINTUBE_ERROR_OUT_OF_RANGE,
                     "chaintube_rig_plug", "socket -1");
        EXPECT_ERROR(chaintube_rig_plug(rig, hoses, 1, 0, &index), CHAINTUBE_ERROR_OUT_OF_RANGE,
                     "hose 2");
        EXPECT_ERROR(chaintube_rig_plug(rig, hose, 0, 0, &index), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                     "takes plugs tagged \"camlock-19\"", "end 0", "left-feed", "has no plug");
        EXPECT_ERROR(chaintube_rig_plug(rig, hose, 1, 0, &index), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                     "end 1", "left-feed", "already attached");
        EXPECT_ERROR(chaintube_rig_plug(rig, hose, 2, 0, &index), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                     "end 2");
        EXPECT_ERROR(chaintube_rig_unplug(rig, hose, 5, &index), CHAINTUBE_ERROR_INVALID_ARGUMENT,
                     "chaintube_rig_unplug", "end 5");
        EXPECT_ERROR(chaintube_rig_unplug(rig, hoses, 1, &index), CHAINTUBE_ERROR_OUT_OF_RANGE,
                     "hose 2");
        EXPECT_ERROR(chaintube_rig_release_snap(rig, -1, &index), CHAINTUBE_ERROR_OUT_OF_RANGE,
                     "hose -1");
        CHECK(socket_info.occupant_hose == 42 && index == 12345, "a refused call wrote an output");
        CHECK(chaintube_rig_socket_info(rig, 0, &socket_info) == CHAINTUBE_OK &&
                  socket_info.occupant_hose == -1 && strcmp(socket_info.tag, "camlock-19") == 0,
              "valve-outlet: occupant %d, tag %s", (int)socket_info.occupant_hose, socket_info.tag);
    }

    /* None of the above changed anything, even after an update. */
    expect_unchanged(__LINE__, rig, node, &before);
    CHECK(chaintube_rig_update(rig, NULL) == CHAINTUBE_OK, "%s", chaintube_last_error());
    expect_unchanged(__LINE__, rig, node, &before);

    /* Sanity: the same calls with good input work and do change the rig. */
    CHECK(chaintube_rig_joint_poses_f64(rig, hose, NULL, 0, doubles, 7 * info.joint_count) ==
              CHAINTUBE_OK,
          "%s", chaintube_last_error());
    target[0] = doubles[7 * point];
    target[1] = doubles[7 * point + 1] + 0.01; /* within reach */
    target[2] = doubles[7 * point + 2];
    CHECK(chaintube_rig_grab(rig, hose, point, target, &result) == CHAINTUBE_OK &&
              result.status == CHAINTUBE_HOSE_OK && result.grab_error < 1e-9 &&
              result.moved_points > 0,
          "status %d, grab error %g, moved %d: %s", (int)result.status, result.grab_error,
          (int)result.moved_points, chaintube_last_error());
    CHECK(chaintube_rig_update(rig, &index) == CHAINTUBE_OK && index >= 1, "%d", (int)index);
    CHECK(chaintube_rig_hose_result(rig, hose, &result) == CHAINTUBE_OK &&
              result.status == CHAINTUBE_HOSE_OK && result.moved_points > 0,
          "frame result: status %d, moved %d", (int)result.status, (int)result.moved_points);
    CHECK(chaintube_rig_joint_poses_f64(rig, hose, NULL, 0, doubles, 7 * info.joint_count) ==
                  CHAINTUBE_OK &&
              fabs(doubles[7 * point] - target[0]) < 1e-9 &&
              fabs(doubles[7 * point + 1] - target[1]) < 1e-9,
          "the grabbed joint is at (%.12g, %.12g), the target at (%.12g, %.12g)",
          doubles[7 * point], doubles[7 * point + 1], target[0], target[1]);
    CHECK(chaintube_rig_release(rig, hose) == CHAINTUBE_OK, "%s", chaintube_last_error());

    /* Tension: right-return drawn taut by its valve moved 10 cm away, slack once it goes back. */
    {
        int32_t right = -1, valve = -1;
        chaintube_node_info valve_info;
        chaintube_hose_info right_info;
        chaintube_attachment_pull pulls[2];
        double home[10], moved[10], parent[10], away[3], length = 0.0;
        static double ends[7 * 256];
        CHECK(chaintube_rig_find_hose(rig, "right-return", &right) == CHAINTUBE_OK &&
                  chaintube_rig_find_node(rig, "valve", &valve) == CHAINTUBE_OK &&
                  chaintube_rig_hose_info(rig, right, &right_info) == CHAINTUBE_OK &&
                  chaintube_rig_node_info(rig, valve, &valve_info) == CHAINTUBE_OK &&
                  chaintube_rig_node_transform(rig, valve, home) == CHAINTUBE_OK &&
                  chaintube_rig_joint_poses_f64(rig, right, NULL, 0, ends, 7 * 256) == CHAINTUBE_OK,
              "%s", chaintube_last_error());
        /* The valve's parent has no rotation or scale: a move in its frame is one in world. */
        CHECK(valve_info.parent < 0 ||
                  (chaintube_rig_node_transform(rig, valve_info.parent, parent) == CHAINTUBE_OK &&
                   parent[6] == 1.0 && parent[7] == 1.0 && parent[8] == 1.0 && parent[9] == 1.0),
              "the valve's parent is rotated or scaled");
        for (int k = 0; k < 3; ++k) {
            away[k] = ends[7 * (right_info.point_count - 1) + k] - ends[k];
            length += away[k] * away[k];
        }
        memcpy(moved, home, sizeof moved);
        for (int frame = 0; frame < 5; ++frame) {
            for (int k = 0; k < 3; ++k)
                moved[k] += 0.02 * away[k] / sqrt(length);
            CHECK(chaintube_rig_set_node_transform(rig, valve, moved) == CHAINTUBE_OK &&
                      chaintube_rig_update(rig, NULL) == CHAINTUBE_OK,
                  "%s", chaintube_last_error());
        }
        for (int32_t a = 0; a < 2; ++a) {
            double along = 0.0;
            CHECK(chaintube_rig_attachment_pull(rig, right, a, 1e4, &pulls[a]) == CHAINTUBE_OK,
                  "%s", chaintube_last_error());
            for (int k = 0; k < 3; ++k)
                along += pulls[a].force[k] * pulls[a].direction[k];
            CHECK(pulls[a].tautness > 0.9 && pulls[a].strain > 0.0 && along > 0.0,
                  "drawn taut, attachment %d: tautness %g, strain %g, force along the pull %g N",
                  (int)a, pulls[a].tautness, pulls[a].strain, along);
        }
        CHECK(chaintube_rig_set_node_transform(rig, valve, home) == CHAINTUBE_OK &&
                  chaintube_rig_update(rig, NULL) == CHAINTUBE_OK,
              "%s", chaintube_last_error());
        for (int32_t a = 0; a < 2; ++a) {
            CHECK(chaintube_rig_attachment_pull(rig, right, a, 1e4, &pulls[a]) == CHAINTUBE_OK,
                  "%s", chaintube_last_error());
            CHECK(pulls[a].tautness == 0.0 && pulls[a].force[0] == 0.0 &&
                      pulls[a].force[1] == 0.0 && pulls[a].force[2] == 0.0,
                  "released, attachment %d: tautness %g", (int)a, pulls[a].tautness);
        }
    }
    CHECK(strcmp(chaintube_status_name(CHAINTUBE_ERROR_BUFFER_TOO_SMALL),
                 "CHAINTUBE_ERROR_BUFFER_TOO_SMALL") == 0 &&
              strcmp(chaintube_status_name((chaintube_status)99), "unknown status") == 0,
          "status names");
    CHECK(chaintube_rig_destroy(rig) == CHAINTUBE_OK, "%s", chaintube_last_error());
}

int main(int argc, char** argv)
{
    if (argc != 4) {
        fprintf(
            stderr,
            "usage: capi_errors_test <test-rig.glb> <rig-options-split.gltf> <scratch folder>\n");
        return 2;
    }
    loading(argv[1], argv[2], argv[3]);
    null_handles();
    per_frame(argv[1]);
    printf("capi_errors_test: %d checks, %d failures\n", cases, failures);
    return failures == 0 ? 0 : 1;
}
