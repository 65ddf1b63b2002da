// The layout of chaintube/runtime_c.h's structs as this build compiled them, for the JavaScript
// API (chaintube.mjs), which reads and writes them in the module's memory: byte offsets and
// sizes, so that the API hard-codes none.
#include "chaintube/runtime_c.h"

#include <cstddef>
#include <string>

namespace {

std::string field(const char* name, size_t offset)
{
    return ",\"" + std::string(name) + "\":" + std::to_string(offset);
}

std::string makeLayout()
{
#define CHAINTUBE_FIELD(type, member) field(#member, offsetof(type, member))
    const std::string hoseInfo =
        "\"hose_info\":{\"sizeof\":" + std::to_string(sizeof(chaintube_hose_info)) +
        CHAINTUBE_FIELD(chaintube_hose_info, id) + CHAINTUBE_FIELD(chaintube_hose_info, name) +
        CHAINTUBE_FIELD(chaintube_hose_info, rest_length) +
        CHAINTUBE_FIELD(chaintube_hose_info, outer_radius) +
        CHAINTUBE_FIELD(chaintube_hose_info, point_count) +
        CHAINTUBE_FIELD(chaintube_hose_info, joint_count) +
        CHAINTUBE_FIELD(chaintube_hose_info, grabbable_count) +
        CHAINTUBE_FIELD(chaintube_hose_info, vertex_count) +
        CHAINTUBE_FIELD(chaintube_hose_info, index_count) +
        CHAINTUBE_FIELD(chaintube_hose_info, mesh_node) +
        CHAINTUBE_FIELD(chaintube_hose_info, skin) +
        CHAINTUBE_FIELD(chaintube_hose_info, is_static) +
        CHAINTUBE_FIELD(chaintube_hose_info, has_gravity) +
        CHAINTUBE_FIELD(chaintube_hose_info, has_torsion) + "}";
    const std::string nodeInfo =
        "\"node_info\":{\"sizeof\":" + std::to_string(sizeof(chaintube_node_info)) +
        CHAINTUBE_FIELD(chaintube_node_info, name) + CHAINTUBE_FIELD(chaintube_node_info, parent) +
        "}";
    const std::string hoseResult =
        "\"hose_result\":{\"sizeof\":" + std::to_string(sizeof(chaintube_hose_result)) +
        CHAINTUBE_FIELD(chaintube_hose_result, status) +
        CHAINTUBE_FIELD(chaintube_hose_result, blocked) +
        CHAINTUBE_FIELD(chaintube_hose_result, length_violation) +
        CHAINTUBE_FIELD(chaintube_hose_result, angle_violation) +
        CHAINTUBE_FIELD(chaintube_hose_result, grab_error) +
        CHAINTUBE_FIELD(chaintube_hose_result, penetration) +
        CHAINTUBE_FIELD(chaintube_hose_result, moved_points) +
        CHAINTUBE_FIELD(chaintube_hose_result, contacts) + "}";
    const std::string clipInfo =
        "\"clip_info\":{\"sizeof\":" + std::to_string(sizeof(chaintube_clip_info)) +
        CHAINTUBE_FIELD(chaintube_clip_info, centre) + CHAINTUBE_FIELD(chaintube_clip_info, axis) +
        CHAINTUBE_FIELD(chaintube_clip_info, slide) +
        CHAINTUBE_FIELD(chaintube_clip_info, slide_min) +
        CHAINTUBE_FIELD(chaintube_clip_info, slide_max) +
        CHAINTUBE_FIELD(chaintube_clip_info, gap) + CHAINTUBE_FIELD(chaintube_clip_info, node) +
        CHAINTUBE_FIELD(chaintube_clip_info, segment) +
        CHAINTUBE_FIELD(chaintube_clip_info, turning) + "}";
    const std::string attachmentPull =
        "\"attachment_pull\":{\"sizeof\":" + std::to_string(sizeof(chaintube_attachment_pull)) +
        CHAINTUBE_FIELD(chaintube_attachment_pull, direction) +
        CHAINTUBE_FIELD(chaintube_attachment_pull, tautness) +
        CHAINTUBE_FIELD(chaintube_attachment_pull, strain) +
        CHAINTUBE_FIELD(chaintube_attachment_pull, force) +
        CHAINTUBE_FIELD(chaintube_attachment_pull, node) +
        CHAINTUBE_FIELD(chaintube_attachment_pull, first_point) +
        CHAINTUBE_FIELD(chaintube_attachment_pull, last_point) +
        CHAINTUBE_FIELD(chaintube_attachment_pull, attached) + "}";
    const std::string socketInfo =
        "\"socket_info\":{\"sizeof\":" + std::to_string(sizeof(chaintube_socket_info)) +
        CHAINTUBE_FIELD(chaintube_socket_info, id) + CHAINTUBE_FIELD(chaintube_socket_info, tag) +
        CHAINTUBE_FIELD(chaintube_socket_info, position) +
        CHAINTUBE_FIELD(chaintube_socket_info, axis) +
        CHAINTUBE_FIELD(chaintube_socket_info, capture_radius) +
        CHAINTUBE_FIELD(chaintube_socket_info, capture_angle) +
        CHAINTUBE_FIELD(chaintube_socket_info, node) +
        CHAINTUBE_FIELD(chaintube_socket_info, occupant_hose) +
        CHAINTUBE_FIELD(chaintube_socket_info, occupant_end) +
        CHAINTUBE_FIELD(chaintube_socket_info, occupant_attachment) + "}";
    const std::string reelResult =
        "\"reel_result\":{\"sizeof\":" + std::to_string(sizeof(chaintube_reel_result)) +
        CHAINTUBE_FIELD(chaintube_reel_result, paid) +
        CHAINTUBE_FIELD(chaintube_reel_result, rest_length) +
        CHAINTUBE_FIELD(chaintube_reel_result, largest_move) +
        CHAINTUBE_FIELD(chaintube_reel_result, message) +
        CHAINTUBE_FIELD(chaintube_reel_result, clamped) +
        CHAINTUBE_FIELD(chaintube_reel_result, segments_added) +
        CHAINTUBE_FIELD(chaintube_reel_result, segments_removed) +
        CHAINTUBE_FIELD(chaintube_reel_result, point_count) + "}";
    const std::string bytes = "\"bytes\":{\"sizeof\":" + std::to_string(sizeof(chaintube_bytes)) +
                              CHAINTUBE_FIELD(chaintube_bytes, data) +
                              CHAINTUBE_FIELD(chaintube_bytes, size) + "}";
#undef CHAINTUBE_FIELD
    return "{" + hoseInfo + "," + nodeInfo + "," + hoseResult + "," + clipInfo + "," +
           attachmentPull + "," + socketInfo + "," + reelResult + "," + bytes + "}";
}

} // namespace

/// The layout as JSON text, e.g. {"hose_info":{"sizeof":64,"id":0,…},"node_info":{…},
/// "hose_result":{…},"clip_info":{…},"attachment_pull":{…},"socket_info":{…},"reel_result":{…},
/// "bytes":{…}}: a
/// static string.
extern "C" const char* chaintube_wasm_struct_layout(void)
{
    static const std::string layout = makeLayout();
    return layout.c_str();
}
