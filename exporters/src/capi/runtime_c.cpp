// The C ABI over rig::HoseRuntime (chaintube/runtime_c.h). Every entry point checks its
// arguments before it changes anything, and runs its body inside guarded(): exceptions become
// a status code and a thread-local message, never cross the boundary.
#include "chaintube/runtime_c.h"

#include "chaintube/export/runtime.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <filesystem>
#include <new>
#include <set>
#include <span>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

struct chaintube_rig
{
    chaintube::rig::HoseRuntime runtime;
    std::vector<std::string> warnings;
    /// Hose ids and names as returned: a cut renames hoses and grows the runtime's list, and a
    /// returned string lives as long as the rig (a std::set never moves its strings).
    mutable std::set<std::string> strings;
    const char* keep(const std::string& text) const { return strings.insert(text).first->c_str(); }
};

namespace {

using chaintube::Status;
using chaintube::UpdateResult;
using chaintube::rig::HoseRuntime;

thread_local std::string t_lastError;
/// Set instead of t_lastError when even the message could not be allocated.
thread_local const char* t_lastErrorFallback = nullptr;

chaintube_status fail(chaintube_status status, const char* function, const std::string& what)
{
    try {
        t_lastError = std::string(function) + ": " + what;
        t_lastErrorFallback = nullptr;
    } catch (...) {
        t_lastErrorFallback = "out of memory while reporting an error";
    }
    return status;
}

/// Runs body() and turns every exception into a status and the last-error message.
template <class Body> chaintube_status guarded(const char* function, Body&& body) noexcept
{
    try {
        return body();
    } catch (const std::bad_alloc&) {
        return fail(CHAINTUBE_ERROR_OUT_OF_MEMORY, function, "out of memory");
    } catch (const chaintube::rig::UnreadableFile& error) {
        return fail(CHAINTUBE_ERROR_UNREADABLE_FILE, function, error.what());
    } catch (const chaintube::Error& error) {
        return fail(CHAINTUBE_ERROR_MALFORMED, function, error.what());
    } catch (const std::exception& error) {
        return fail(CHAINTUBE_ERROR_INTERNAL, function, error.what());
    } catch (...) {
        return fail(CHAINTUBE_ERROR_INTERNAL, function, "unknown exception");
    }
}

std::string versionText(uint32_t version)
{
    return std::to_string(version >> 16) + "." + std::to_string(version & 0xFFFFu);
}

chaintube_status checkAbi(const char* function, uint32_t callerVersion)
{
    const uint32_t library = CHAINTUBE_RUNTIME_ABI_VERSION;
    if (callerVersion >> 16 != library >> 16 || (callerVersion & 0xFFFFu) > (library & 0xFFFFu))
        return fail(CHAINTUBE_ERROR_ABI_MISMATCH, function,
                    "the caller was built against ChainTube runtime ABI " +
                        versionText(callerVersion) + ", this library is ABI " +
                        versionText(library) +
                        " (expected the same major version and a minor version no newer than "
                        "the library's): rebuild against this library's chaintube/runtime_c.h");
    return CHAINTUBE_OK;
}

chaintube_status nullArgument(const char* function, const char* argument)
{
    return fail(CHAINTUBE_ERROR_INVALID_ARGUMENT, function,
                std::string(argument) + " is NULL: expected a valid pointer");
}

chaintube_status checkHose(const char* function, const chaintube_rig* rig, int32_t hose)
{
    if (!rig) return nullArgument(function, "rig");
    if (hose < 0 || hose >= rig->runtime.hoseCount())
        return fail(CHAINTUBE_ERROR_OUT_OF_RANGE, function,
                    "hose " + std::to_string(hose) + " is out of range: expected 0 to " +
                        std::to_string(rig->runtime.hoseCount() - 1) + " (" +
                        std::to_string(rig->runtime.hoseCount()) + " hoses)");
    return CHAINTUBE_OK;
}

chaintube_status checkNode(const char* function, const chaintube_rig* rig, int32_t node)
{
    if (!rig) return nullArgument(function, "rig");
    if (node < 0 || node >= rig->runtime.nodeCount())
        return fail(CHAINTUBE_ERROR_OUT_OF_RANGE, function,
                    "node " + std::to_string(node) + " is out of range: expected 0 to " +
                        std::to_string(rig->runtime.nodeCount() - 1) + " (" +
                        std::to_string(rig->runtime.nodeCount()) + " nodes)");
    return CHAINTUBE_OK;
}

std::string hoseName(const chaintube_rig* rig, int32_t hose)
{
    return "hose " + std::to_string(hose) + " (\"" + rig->runtime.description(hose).id + "\")";
}

/// A caller's buffer of `capacity` elements that must hold `needed`.
chaintube_status checkCapacity(const char* function, const char* argument, int32_t capacity,
                               size_t needed, const std::string& forWhat)
{
    if (capacity < 0 || static_cast<size_t>(capacity) < needed)
        return fail(CHAINTUBE_ERROR_BUFFER_TOO_SMALL, function,
                    std::string(argument) + " has room for " + std::to_string(capacity) +
                        " elements: " + forWhat + " needs at least " + std::to_string(needed));
    return CHAINTUBE_OK;
}

/// Two optional output buffers, at least one given, each large enough.
chaintube_status checkOutputs(const char* function, const void* first, const char* firstName,
                              int32_t firstCapacity, size_t firstNeeded, const void* second,
                              const char* secondName, int32_t secondCapacity, size_t secondNeeded,
                              const std::string& forWhat)
{
    if (!first && !second)
        return fail(CHAINTUBE_ERROR_INVALID_ARGUMENT, function,
                    std::string(firstName) + " and " + secondName +
                        " are both NULL: expected at least one buffer to write");
    if (first)
        if (const chaintube_status status =
                checkCapacity(function, firstName, firstCapacity, firstNeeded, forWhat))
            return status;
    if (second)
        if (const chaintube_status status =
                checkCapacity(function, secondName, secondCapacity, secondNeeded, forWhat))
            return status;
    return CHAINTUBE_OK;
}

chaintube_hose_result resultOf(const UpdateResult& result)
{
    chaintube_hose_result out{};
    switch (result.status) { // no default: a new library status must be mapped here
    case Status::Ok:
        out.status = CHAINTUBE_HOSE_OK;
        break;
    case Status::Clamped:
        out.status = CHAINTUBE_HOSE_CLAMPED;
        break;
    case Status::Infeasible:
        out.status = CHAINTUBE_HOSE_INFEASIBLE;
        break;
    case Status::InvalidInput:
        out.status = CHAINTUBE_HOSE_OK;
        break; // never reported: refused
    }
    out.blocked = result.blocked ? 1 : 0;
    out.length_violation = result.lengthViolation;
    out.angle_violation = result.angleViolation;
    out.grab_error = result.grabError;
    out.penetration = result.penetration;
    out.moved_points = result.movedPoints;
    out.contacts = result.contacts;
    return out;
}

std::string numberText(double value)
{
    if (std::isnan(value)) return "NaN";
    if (std::isinf(value)) return value > 0 ? "+Inf" : "-Inf";
    return std::to_string(value);
}

/// Writes a joint's poses as 10 + 7 numbers of type Real.
template <class Real>
void writePose(const chaintube::rig::JointPose& pose, Real* local, Real* world)
{
    if (local) {
        const chaintube::rig::NodeTransform& trs = pose.local;
        const double values[10] = {trs.translation.x(), trs.translation.y(), trs.translation.z(),
                                   trs.rotation.x(),    trs.rotation.y(),    trs.rotation.z(),
                                   trs.rotation.w(),    trs.scale.x(),       trs.scale.y(),
                                   trs.scale.z()};
        for (int k = 0; k < 10; ++k)
            local[k] = static_cast<Real>(values[k]);
    }
    if (world) {
        const chaintube::Frame& frame = pose.world;
        const double values[7] = {
            frame.translation.x(), frame.translation.y(), frame.translation.z(), frame.rotation.x(),
            frame.rotation.y(),    frame.rotation.z(),    frame.rotation.w()};
        for (int k = 0; k < 7; ++k)
            world[k] = static_cast<Real>(values[k]);
    }
}

template <class Real>
chaintube_status jointPoses(const char* function, const chaintube_rig* rig, int32_t hose,
                            Real* local, int32_t localCapacity, Real* world, int32_t worldCapacity)
{
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkHose(function, rig, hose)) return status;
        const std::vector<chaintube::rig::JointPose>& poses = rig->runtime.jointPoses(hose);
        const std::string forWhat =
            hoseName(rig, hose) + " with " + std::to_string(poses.size()) + " joints";
        if (const chaintube_status status =
                checkOutputs(function, local, "local", localCapacity, 10 * poses.size(), world,
                             "world", worldCapacity, 7 * poses.size(), forWhat))
            return status;
        for (size_t j = 0; j < poses.size(); ++j)
            writePose(poses[j], local ? local + 10 * j : nullptr, world ? world + 7 * j : nullptr);
        return CHAINTUBE_OK;
    });
}

chaintube_status adopt(chaintube::rig::HoseRuntime&& runtime,
                       chaintube::rig::RuntimeLoadReport&& report, chaintube_rig** rig)
{
    *rig = new chaintube_rig{std::move(runtime), std::move(report.warnings), {}};
    return CHAINTUBE_OK;
}

} // namespace

extern "C" {

uint32_t chaintube_runtime_abi_version(void)
{
    return CHAINTUBE_RUNTIME_ABI_VERSION;
}

const char* chaintube_status_name(chaintube_status status)
{
    // A C caller may pass any int: read it as one (an enum outside its enumerators' range is
    // undefined behaviour in C++).
    int value = 0;
    static_assert(sizeof value == sizeof status);
    std::memcpy(&value, &status, sizeof value);
    switch (value) {
    case CHAINTUBE_OK:
        return "CHAINTUBE_OK";
    case CHAINTUBE_ERROR_INVALID_ARGUMENT:
        return "CHAINTUBE_ERROR_INVALID_ARGUMENT";
    case CHAINTUBE_ERROR_OUT_OF_RANGE:
        return "CHAINTUBE_ERROR_OUT_OF_RANGE";
    case CHAINTUBE_ERROR_BUFFER_TOO_SMALL:
        return "CHAINTUBE_ERROR_BUFFER_TOO_SMALL";
    case CHAINTUBE_ERROR_NOT_FOUND:
        return "CHAINTUBE_ERROR_NOT_FOUND";
    case CHAINTUBE_ERROR_NOT_GRABBABLE:
        return "CHAINTUBE_ERROR_NOT_GRABBABLE";
    case CHAINTUBE_ERROR_ABI_MISMATCH:
        return "CHAINTUBE_ERROR_ABI_MISMATCH";
    case CHAINTUBE_ERROR_UNREADABLE_FILE:
        return "CHAINTUBE_ERROR_UNREADABLE_FILE";
    case CHAINTUBE_ERROR_MALFORMED:
        return "CHAINTUBE_ERROR_MALFORMED";
    case CHAINTUBE_ERROR_OUT_OF_MEMORY:
        return "CHAINTUBE_ERROR_OUT_OF_MEMORY";
    case CHAINTUBE_ERROR_INTERNAL:
        return "CHAINTUBE_ERROR_INTERNAL";
    }
    return "unknown status";
}

const char* chaintube_last_error(void)
{
    return t_lastErrorFallback ? t_lastErrorFallback : t_lastError.c_str();
}

chaintube_status chaintube_rig_load_file(uint32_t abi_version, const char* path,
                                         chaintube_rig** rig)
{
    constexpr const char* function = "chaintube_rig_load_file";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkAbi(function, abi_version)) return status;
        if (!path) return nullArgument(function, "path");
        if (!rig) return nullArgument(function, "rig");
        chaintube::rig::RuntimeLoadReport report;
        // The path is UTF-8 whatever the locale: std::filesystem::path from char8_t.
        const std::string text(path);
        const std::filesystem::path file(std::u8string(text.begin(), text.end()));
        HoseRuntime runtime = HoseRuntime::load(file, &report);
        return adopt(std::move(runtime), std::move(report), rig);
    });
}

chaintube_status chaintube_rig_load_memory(uint32_t abi_version, const char* name, const void* gltf,
                                           size_t gltf_size, const chaintube_bytes* buffers,
                                           int32_t buffer_count, const void* sidecar,
                                           size_t sidecar_size, chaintube_rig** rig)
{
    constexpr const char* function = "chaintube_rig_load_memory";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkAbi(function, abi_version)) return status;
        if (!gltf) return nullArgument(function, "gltf");
        if (!rig) return nullArgument(function, "rig");
        if (buffer_count < 0)
            return fail(CHAINTUBE_ERROR_INVALID_ARGUMENT, function,
                        "buffer_count is " + std::to_string(buffer_count) + ": expected 0 or more");
        if (buffer_count > 0 && !buffers) return nullArgument(function, "buffers");
        if (sidecar_size > 0 && !sidecar) return nullArgument(function, "sidecar");
        chaintube::rig::ExportInMemory source;
        if (name) source.name = name;
        source.gltf = std::string_view(static_cast<const char*>(gltf), gltf_size);
        for (int32_t b = 0; b < buffer_count; ++b) {
            if (!buffers[b].data && buffers[b].size > 0)
                return fail(CHAINTUBE_ERROR_INVALID_ARGUMENT, function,
                            "buffers[" + std::to_string(b) + "].data is NULL but its size is " +
                                std::to_string(buffers[b].size) +
                                ": expected the bytes, or {NULL, 0} for a buffer not given");
            source.buffers.emplace_back(static_cast<const char*>(buffers[b].data), buffers[b].size);
        }
        if (sidecar)
            source.sidecarDescriptor =
                std::string_view(static_cast<const char*>(sidecar), sidecar_size);
        chaintube::rig::RuntimeLoadReport report;
        HoseRuntime runtime = HoseRuntime::loadFromMemory(source, &report);
        return adopt(std::move(runtime), std::move(report), rig);
    });
}

chaintube_status chaintube_rig_destroy(chaintube_rig* rig)
{
    return guarded("chaintube_rig_destroy", [&]() -> chaintube_status {
        delete rig;
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_warning_count(const chaintube_rig* rig, int32_t* count)
{
    constexpr const char* function = "chaintube_rig_warning_count";
    return guarded(function, [&]() -> chaintube_status {
        if (!rig) return nullArgument(function, "rig");
        if (!count) return nullArgument(function, "count");
        *count = static_cast<int32_t>(rig->warnings.size());
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_warning(const chaintube_rig* rig, int32_t index, const char** text)
{
    constexpr const char* function = "chaintube_rig_warning";
    return guarded(function, [&]() -> chaintube_status {
        if (!rig) return nullArgument(function, "rig");
        if (!text) return nullArgument(function, "text");
        if (index < 0 || static_cast<size_t>(index) >= rig->warnings.size())
            return fail(CHAINTUBE_ERROR_OUT_OF_RANGE, function,
                        "warning " + std::to_string(index) + " is out of range: the rig has " +
                            std::to_string(rig->warnings.size()) + " warnings");
        *text = rig->warnings[static_cast<size_t>(index)].c_str();
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_hose_count(const chaintube_rig* rig, int32_t* count)
{
    constexpr const char* function = "chaintube_rig_hose_count";
    return guarded(function, [&]() -> chaintube_status {
        if (!rig) return nullArgument(function, "rig");
        if (!count) return nullArgument(function, "count");
        *count = rig->runtime.hoseCount();
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_node_count(const chaintube_rig* rig, int32_t* count)
{
    constexpr const char* function = "chaintube_rig_node_count";
    return guarded(function, [&]() -> chaintube_status {
        if (!rig) return nullArgument(function, "rig");
        if (!count) return nullArgument(function, "count");
        *count = rig->runtime.nodeCount();
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_find_hose(const chaintube_rig* rig, const char* id, int32_t* hose)
{
    constexpr const char* function = "chaintube_rig_find_hose";
    return guarded(function, [&]() -> chaintube_status {
        if (!rig) return nullArgument(function, "rig");
        if (!id) return nullArgument(function, "id");
        if (!hose) return nullArgument(function, "hose");
        const int found = rig->runtime.findHose(id);
        if (found < 0)
            return fail(CHAINTUBE_ERROR_NOT_FOUND, function,
                        "no hose has the id \"" + std::string(id) + "\"");
        *hose = found;
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_find_node(const chaintube_rig* rig, const char* name, int32_t* node)
{
    constexpr const char* function = "chaintube_rig_find_node";
    return guarded(function, [&]() -> chaintube_status {
        if (!rig) return nullArgument(function, "rig");
        if (!name) return nullArgument(function, "name");
        if (!node) return nullArgument(function, "node");
        const int found = rig->runtime.findNode(name);
        if (found < 0)
            return fail(CHAINTUBE_ERROR_NOT_FOUND, function,
                        "no node is named \"" + std::string(name) + "\"");
        *node = found;
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_hose_info(const chaintube_rig* rig, int32_t hose,
                                         chaintube_hose_info* info)
{
    constexpr const char* function = "chaintube_rig_hose_info";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkHose(function, rig, hose)) return status;
        if (!info) return nullArgument(function, "info");
        const chaintube::rig::RigHose& description = rig->runtime.description(hose);
        const chaintube::Hose& running = rig->runtime.hose(hose);
        const chaintube::HoseSurface& surface = rig->runtime.surface(hose);
        chaintube_hose_info out{};
        out.id = rig->keep(description.id);
        out.name = rig->keep(description.name);
        out.rest_length = running.restLengthTotal();
        out.outer_radius = running.outerRadius();
        out.point_count = running.pointCount();
        out.joint_count = static_cast<int32_t>(rig->runtime.jointPoses(hose).size());
        out.grabbable_count = static_cast<int32_t>(rig->runtime.grabbablePoints(hose).size());
        out.vertex_count = static_cast<int32_t>(surface.vertexCount());
        out.index_count = static_cast<int32_t>(surface.topology().indices.size());
        out.mesh_node = description.meshNode;
        out.skin = description.skin;
        out.is_static = description.isStatic ? 1 : 0;
        out.has_gravity = running.spec().gravity.enabled ? 1 : 0;
        out.has_torsion = running.spec().torsion.enabled ? 1 : 0;
        *info = out;
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_grabbable_points(const chaintube_rig* rig, int32_t hose,
                                                int32_t* points, int32_t capacity)
{
    constexpr const char* function = "chaintube_rig_grabbable_points";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkHose(function, rig, hose)) return status;
        const std::vector<int>& grabbable = rig->runtime.grabbablePoints(hose);
        if (!points && !grabbable.empty()) return nullArgument(function, "points");
        if (const chaintube_status status =
                checkCapacity(function, "points", capacity, grabbable.size(),
                              hoseName(rig, hose) + " with " + std::to_string(grabbable.size()) +
                                  " grabbable points"))
            return status;
        for (size_t i = 0; i < grabbable.size(); ++i)
            points[i] = grabbable[i];
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_joint_nodes(const chaintube_rig* rig, int32_t hose, int32_t* nodes,
                                           int32_t capacity)
{
    constexpr const char* function = "chaintube_rig_joint_nodes";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkHose(function, rig, hose)) return status;
        const std::vector<chaintube::rig::JointPose>& poses = rig->runtime.jointPoses(hose);
        if (!nodes && !poses.empty()) return nullArgument(function, "nodes");
        if (const chaintube_status status = checkCapacity(
                function, "nodes", capacity, poses.size(),
                hoseName(rig, hose) + " with " + std::to_string(poses.size()) + " joints"))
            return status;
        for (size_t j = 0; j < poses.size(); ++j)
            nodes[j] = poses[j].node;
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_rest_lengths(const chaintube_rig* rig, int32_t hose,
                                            double* rest_lengths, int32_t capacity,
                                            double* expansion_coefficient)
{
    constexpr const char* function = "chaintube_rig_rest_lengths";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkHose(function, rig, hose)) return status;
        if (!rest_lengths && !expansion_coefficient)
            return fail(CHAINTUBE_ERROR_INVALID_ARGUMENT, function,
                        "rest_lengths and expansion_coefficient are both NULL: expected at least "
                        "one output to write");
        const chaintube::Hose& running = rig->runtime.hose(hose);
        const size_t segments = static_cast<size_t>(running.segmentCount());
        if (rest_lengths)
            if (const chaintube_status status = checkCapacity(
                    function, "rest_lengths", capacity, segments,
                    hoseName(rig, hose) + " with " + std::to_string(segments) + " segments"))
                return status;
        if (rest_lengths)
            for (size_t s = 0; s < segments; ++s)
                rest_lengths[s] = running.restLength(static_cast<int>(s));
        if (expansion_coefficient) *expansion_coefficient = running.material().expansionCoefficient;
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_clip_count(const chaintube_rig* rig, int32_t hose, int32_t* count)
{
    constexpr const char* function = "chaintube_rig_clip_count";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkHose(function, rig, hose)) return status;
        if (!count) return nullArgument(function, "count");
        *count = static_cast<int32_t>(rig->runtime.description(hose).clips.size());
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_clip_info(const chaintube_rig* rig, int32_t hose, int32_t clip,
                                         chaintube_clip_info* info)
{
    constexpr const char* function = "chaintube_rig_clip_info";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkHose(function, rig, hose)) return status;
        const std::vector<chaintube::rig::RigClip>& clips = rig->runtime.description(hose).clips;
        if (clip < 0 || static_cast<size_t>(clip) >= clips.size())
            return fail(CHAINTUBE_ERROR_OUT_OF_RANGE, function,
                        "clip " + std::to_string(clip) +
                            " is out of range: " + hoseName(rig, hose) + " has " +
                            std::to_string(clips.size()) + " clips (chaintube_rig_clip_count)");
        if (!info) return nullArgument(function, "info");
        const chaintube::Hose::Attachment& held = rig->runtime.clip(hose, clip);
        const chaintube::Vec3 centre = held.frame.apply(held.clipCentre);
        const chaintube::Vec3 axis = (held.frame.rotation * held.clipAxis).normalized();
        chaintube_clip_info out{};
        for (int k = 0; k < 3; ++k) {
            out.centre[k] = centre(k);
            out.axis[k] = axis(k);
        }
        out.slide = held.slide;
        out.slide_min = held.slideMin;
        out.slide_max = held.slideMax;
        out.gap = rig->runtime.hose(hose).attachmentGap(held.id);
        out.node = clips[static_cast<size_t>(clip)].node;
        out.segment = held.first;
        out.turning = held.hold == chaintube::Hold::SlidingTurning ? 1 : 0;
        *info = out;
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_attachment_count(const chaintube_rig* rig, int32_t hose,
                                                int32_t* count)
{
    constexpr const char* function = "chaintube_rig_attachment_count";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkHose(function, rig, hose)) return status;
        if (!count) return nullArgument(function, "count");
        *count = rig->runtime.attachmentCount(hose);
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_attachment_pull(const chaintube_rig* rig, int32_t hose,
                                               int32_t attachment, double axial_stiffness,
                                               chaintube_attachment_pull* pull)
{
    constexpr const char* function = "chaintube_rig_attachment_pull";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkHose(function, rig, hose)) return status;
        if (!std::isfinite(axial_stiffness) || axial_stiffness < 0.0)
            return fail(CHAINTUBE_ERROR_INVALID_ARGUMENT, function,
                        "axial_stiffness is " + std::to_string(axial_stiffness) +
                            ": expected a finite EA >= 0 (newtons per unit strain)");
        const int count = rig->runtime.attachmentCount(hose);
        if (attachment < 0 || attachment >= count)
            return fail(CHAINTUBE_ERROR_OUT_OF_RANGE, function,
                        "attachment " + std::to_string(attachment) + " is out of range: " +
                            hoseName(rig, hose) + " has " + std::to_string(count) +
                            " attachments (chaintube_rig_attachment_count)");
        if (!pull) return nullArgument(function, "pull");
        const chaintube::AttachmentPull& measured = rig->runtime.attachmentPull(hose, attachment);
        const chaintube::Vec3 force = measured.force(axial_stiffness);
        const chaintube::rig::LiveAttachment& described = rig->runtime.attachment(hose, attachment);
        chaintube_attachment_pull out{};
        for (int k = 0; k < 3; ++k) {
            out.direction[k] = measured.direction(k);
            out.force[k] = force(k);
        }
        out.tautness = measured.tautness;
        out.strain = measured.strain;
        out.node = described.node;
        out.first_point = described.firstPoint;
        out.last_point = described.lastPoint;
        out.attached = described.attached ? 1 : 0;
        *pull = out;
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_node_info(const chaintube_rig* rig, int32_t node,
                                         chaintube_node_info* info)
{
    constexpr const char* function = "chaintube_rig_node_info";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkNode(function, rig, node)) return status;
        if (!info) return nullArgument(function, "info");
        const chaintube::rig::RigNode& rigNode = rig->runtime.node(node);
        info->name = rigNode.name.c_str();
        info->parent = rigNode.parent;
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_node_transform(const chaintube_rig* rig, int32_t node,
                                              double trs[10])
{
    constexpr const char* function = "chaintube_rig_node_transform";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkNode(function, rig, node)) return status;
        if (!trs) return nullArgument(function, "trs");
        chaintube::rig::JointPose pose;
        pose.local = rig->runtime.node(node).local;
        writePose<double>(pose, trs, nullptr);
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_set_node_transform(chaintube_rig* rig, int32_t node,
                                                  const double trs[10])
{
    constexpr const char* function = "chaintube_rig_set_node_transform";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkNode(function, rig, node)) return status;
        if (!trs) return nullArgument(function, "trs");
        static const char* const names[10] = {
            "translation x", "translation y", "translation z", "rotation x", "rotation y",
            "rotation z",    "rotation w",    "scale x",       "scale y",    "scale z"};
        for (int k = 0; k < 10; ++k)
            if (!std::isfinite(trs[k]))
                return fail(CHAINTUBE_ERROR_INVALID_ARGUMENT, function,
                            "trs[" + std::to_string(k) + "] (" + names[k] + ") is " +
                                numberText(trs[k]) + ": expected a finite number");
        for (int k = 7; k < 10; ++k)
            if (trs[k] == 0.0)
                return fail(CHAINTUBE_ERROR_INVALID_ARGUMENT, function,
                            "trs[" + std::to_string(k) + "] (" + names[k] +
                                ") is 0: expected a non-zero scale (a zero scale flattens the "
                                "node's children onto a plane that no transform can undo)");
        chaintube::rig::NodeTransform local;
        local.translation = chaintube::Vec3(trs[0], trs[1], trs[2]);
        local.rotation = chaintube::Quat(trs[6], trs[3], trs[4], trs[5]);
        local.scale = chaintube::Vec3(trs[7], trs[8], trs[9]);
        if (!(local.rotation.norm() > 0.5)) // as the runtime: it normalises the rest
            return fail(CHAINTUBE_ERROR_INVALID_ARGUMENT, function,
                        "trs[3..6] (rotation x, y, z, w) has length " +
                            numberText(local.rotation.norm()) + ": expected a unit quaternion");
        const std::vector<chaintube::rig::HoseUpdate> updates =
            rig->runtime.setNodeTransform(node, local);
        for (const chaintube::rig::HoseUpdate& update : updates)
            if (update.hose < 0) // refused by the runtime: nothing changed
                return fail(CHAINTUBE_ERROR_INVALID_ARGUMENT, function,
                            "the runtime refused the transform of node " + std::to_string(node));
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_grab(chaintube_rig* rig, int32_t hose, int32_t point,
                                    const double target[3], chaintube_hose_result* result)
{
    constexpr const char* function = "chaintube_rig_grab";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkHose(function, rig, hose)) return status;
        if (!target) return nullArgument(function, "target");
        for (int k = 0; k < 3; ++k)
            if (!std::isfinite(target[k]))
                return fail(CHAINTUBE_ERROR_INVALID_ARGUMENT, function,
                            "target[" + std::to_string(k) + "] is " + numberText(target[k]) +
                                ": expected a finite number (world metres)");
        const int points = rig->runtime.hose(hose).pointCount();
        if (point < 0 || point >= points)
            return fail(CHAINTUBE_ERROR_OUT_OF_RANGE, function,
                        "point " + std::to_string(point) + " is out of range: " +
                            hoseName(rig, hose) + " has points 0 to " + std::to_string(points - 1));
        const std::vector<int>& grabbable = rig->runtime.grabbablePoints(hose);
        if (!std::binary_search(grabbable.begin(), grabbable.end(), point))
            return fail(CHAINTUBE_ERROR_NOT_GRABBABLE, function,
                        "point " + std::to_string(point) + " of " + hoseName(rig, hose) +
                            " is not grabbable: expected one of its " +
                            std::to_string(grabbable.size()) +
                            " free points (chaintube_rig_grabbable_points)");
        if (rig->runtime.hose(hose).isFixed(point)) // a clip slid onto it
            return fail(CHAINTUBE_ERROR_NOT_GRABBABLE, function,
                        "point " + std::to_string(point) + " of " + hoseName(rig, hose) +
                            " is held by a clip now (chaintube_rig_clip_info): expected a point "
                            "no clip holds");
        const UpdateResult outcome =
            rig->runtime.grab(hose, point, chaintube::Vec3(target[0], target[1], target[2]));
        if (outcome.status == Status::InvalidInput)
            return fail(CHAINTUBE_ERROR_INVALID_ARGUMENT, function,
                        "the runtime refused the grab of point " + std::to_string(point) + " of " +
                            hoseName(rig, hose));
        if (result) *result = resultOf(outcome);
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_detach_end(chaintube_rig* rig, int32_t hose, int32_t attachment,
                                          chaintube_hose_result* result)
{
    constexpr const char* function = "chaintube_rig_detach_end";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkHose(function, rig, hose)) return status;
        const int count = rig->runtime.attachmentCount(hose);
        if (attachment < 0 || attachment >= count)
            return fail(CHAINTUBE_ERROR_OUT_OF_RANGE, function,
                        "attachment " + std::to_string(attachment) + " is out of range: " +
                            hoseName(rig, hose) + " has " + std::to_string(count) +
                            " attachments (chaintube_rig_attachment_count)");
        std::string why;
        const UpdateResult outcome = rig->runtime.detachEnd(hose, attachment, &why);
        if (outcome.status == Status::InvalidInput)
            return fail(CHAINTUBE_ERROR_INVALID_ARGUMENT, function, why);
        if (result) *result = resultOf(outcome);
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_attach_end(chaintube_rig* rig, int32_t hose, int32_t end,
                                          int32_t node, const double pose[7], int32_t* attachment,
                                          chaintube_hose_result* result)
{
    constexpr const char* function = "chaintube_rig_attach_end";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkHose(function, rig, hose)) return status;
        if (node != -1)
            if (const chaintube_status status = checkNode(function, rig, node)) return status;
        if (end != 0 && end != 1)
            return fail(CHAINTUBE_ERROR_INVALID_ARGUMENT, function,
                        "end " + std::to_string(end) +
                            ": expected 0 (the first point's end) or 1 (the last point's)");
        if (!pose) return nullArgument(function, "pose");
        static const char* const names[7] = {"translation x", "translation y", "translation z",
                                             "rotation x",    "rotation y",    "rotation z",
                                             "rotation w"};
        for (int k = 0; k < 7; ++k)
            if (!std::isfinite(pose[k]))
                return fail(CHAINTUBE_ERROR_INVALID_ARGUMENT, function,
                            "pose[" + std::to_string(k) + "] (" + names[k] + ") is " +
                                numberText(pose[k]) + ": expected a finite number");
        chaintube::Frame local;
        local.translation = chaintube::Vec3(pose[0], pose[1], pose[2]);
        local.rotation = chaintube::Quat(pose[6], pose[3], pose[4], pose[5]);
        if (!(local.rotation.norm() > 0.5))
            return fail(CHAINTUBE_ERROR_INVALID_ARGUMENT, function,
                        "the rotation pose[3..6] has length " + numberText(local.rotation.norm()) +
                            ": expected a unit quaternion");
        std::string why;
        int index = -1;
        const UpdateResult outcome = rig->runtime.attachEnd(hose, end, node, local, &index, &why);
        if (outcome.status == Status::InvalidInput)
            return fail(CHAINTUBE_ERROR_INVALID_ARGUMENT, function, why);
        if (attachment) *attachment = index;
        if (result) *result = resultOf(outcome);
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_cut(chaintube_rig* rig, int32_t hose, int32_t point,
                                   int32_t* new_hose)
{
    constexpr const char* function = "chaintube_rig_cut";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkHose(function, rig, hose)) return status;
        const int points = rig->runtime.hose(hose).pointCount();
        if (point < 0 || point >= points)
            return fail(CHAINTUBE_ERROR_OUT_OF_RANGE, function,
                        "point " + std::to_string(point) + " is out of range: " +
                            hoseName(rig, hose) + " has points 0 to " + std::to_string(points - 1));
        std::string why;
        const chaintube::rig::CutResult outcome = rig->runtime.cut(hose, point, &why);
        if (outcome.status == Status::InvalidInput)
            return fail(CHAINTUBE_ERROR_INVALID_ARGUMENT, function, why);
        if (new_hose) *new_hose = outcome.newHose;
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_release(chaintube_rig* rig, int32_t hose)
{
    constexpr const char* function = "chaintube_rig_release";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkHose(function, rig, hose)) return status;
        (void)rig->runtime.release(hose);
        return CHAINTUBE_OK;
    });
}

// ---- Sockets (ABI 1.3) ----

chaintube_status chaintube_rig_socket_count(const chaintube_rig* rig, int32_t* count)
{
    constexpr const char* function = "chaintube_rig_socket_count";
    return guarded(function, [&]() -> chaintube_status {
        if (!rig) return nullArgument(function, "rig");
        if (!count) return nullArgument(function, "count");
        *count = rig->runtime.socketCount();
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_find_socket(const chaintube_rig* rig, const char* id,
                                           int32_t* socket)
{
    constexpr const char* function = "chaintube_rig_find_socket";
    return guarded(function, [&]() -> chaintube_status {
        if (!rig) return nullArgument(function, "rig");
        if (!id) return nullArgument(function, "id");
        if (!socket) return nullArgument(function, "socket");
        const int found = rig->runtime.findSocket(id);
        if (found < 0)
            return fail(CHAINTUBE_ERROR_NOT_FOUND, function,
                        "no socket has the id \"" + std::string(id) + "\" (" +
                            std::to_string(rig->runtime.socketCount()) + " sockets)");
        *socket = found;
        return CHAINTUBE_OK;
    });
}

namespace {
chaintube_status checkSocket(const char* function, const chaintube_rig* rig, int32_t socket)
{
    if (!rig) return nullArgument(function, "rig");
    if (socket < 0 || socket >= rig->runtime.socketCount())
        return fail(CHAINTUBE_ERROR_OUT_OF_RANGE, function,
                    "socket " + std::to_string(socket) + " is out of range: expected 0 to " +
                        std::to_string(rig->runtime.socketCount() - 1) + " (" +
                        std::to_string(rig->runtime.socketCount()) + " sockets)");
    return CHAINTUBE_OK;
}
} // namespace

chaintube_status chaintube_rig_socket_info(const chaintube_rig* rig, int32_t socket,
                                           chaintube_socket_info* info)
{
    constexpr const char* function = "chaintube_rig_socket_info";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkSocket(function, rig, socket)) return status;
        if (!info) return nullArgument(function, "info");
        const HoseRuntime::SocketPose pose = rig->runtime.socket(socket);
        const chaintube::rig::SocketOccupant occupant = rig->runtime.socketOccupant(socket);
        chaintube_socket_info out{};
        out.id = pose.description->id.c_str();
        out.tag = pose.description->tag.c_str();
        for (int k = 0; k < 3; ++k) {
            out.position[k] = pose.position(k);
            out.axis[k] = pose.axis(k);
        }
        out.capture_radius = pose.description->captureRadius;
        out.capture_angle = pose.description->captureAngle;
        out.node = pose.description->node;
        out.occupant_hose = occupant.hose;
        out.occupant_end = occupant.end;
        out.occupant_attachment = occupant.attachment;
        *info = out;
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_release_snap(chaintube_rig* rig, int32_t hose, int32_t* socket)
{
    constexpr const char* function = "chaintube_rig_release_snap";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkHose(function, rig, hose)) return status;
        const chaintube::rig::PlugResult released = rig->runtime.release(hose);
        if (!released)
            return fail(CHAINTUBE_ERROR_INTERNAL, function,
                        "the runtime refused the release of " + hoseName(rig, hose));
        if (socket) *socket = released.socket;
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_plug(chaintube_rig* rig, int32_t hose, int32_t end, int32_t socket,
                                    int32_t* attachment)
{
    constexpr const char* function = "chaintube_rig_plug";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkHose(function, rig, hose)) return status;
        if (const chaintube_status status = checkSocket(function, rig, socket)) return status;
        std::string why;
        const chaintube::rig::PlugResult plugged = rig->runtime.plug(hose, end, socket, &why);
        if (!plugged) return fail(CHAINTUBE_ERROR_INVALID_ARGUMENT, function, why);
        if (attachment) *attachment = plugged.attachment;
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_unplug(chaintube_rig* rig, int32_t hose, int32_t end,
                                      int32_t* socket)
{
    constexpr const char* function = "chaintube_rig_unplug";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkHose(function, rig, hose)) return status;
        std::string why;
        const chaintube::rig::PlugResult unplugged = rig->runtime.unplug(hose, end, &why);
        if (!unplugged) return fail(CHAINTUBE_ERROR_INVALID_ARGUMENT, function, why);
        if (socket) *socket = unplugged.socket;
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_update(chaintube_rig* rig, int32_t* recomputed)
{
    constexpr const char* function = "chaintube_rig_update";
    return guarded(function, [&]() -> chaintube_status {
        if (!rig) return nullArgument(function, "rig");
        const int changed = rig->runtime.update();
        if (recomputed) *recomputed = changed;
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_update_seconds(chaintube_rig* rig, double seconds,
                                              int32_t* recomputed)
{
    constexpr const char* function = "chaintube_rig_update_seconds";
    return guarded(function, [&]() -> chaintube_status {
        if (!rig) return nullArgument(function, "rig");
        if (!std::isfinite(seconds) || !(seconds > 0.0) ||
            seconds > chaintube::Gravity::kMaxFrameSeconds) {
            std::ostringstream text;
            text << "seconds: expected the frame's time in (0, "
                 << chaintube::Gravity::kMaxFrameSeconds << "] s, got " << seconds;
            return fail(CHAINTUBE_ERROR_INVALID_ARGUMENT, function, text.str());
        }
        const int changed = rig->runtime.update(seconds);
        if (recomputed) *recomputed = changed;
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_hose_result(const chaintube_rig* rig, int32_t hose,
                                           chaintube_hose_result* result)
{
    constexpr const char* function = "chaintube_rig_hose_result";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkHose(function, rig, hose)) return status;
        if (!result) return nullArgument(function, "result");
        *result = resultOf(rig->runtime.frameResult(hose));
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_joint_poses(const chaintube_rig* rig, int32_t hose, float* local,
                                           int32_t local_capacity, float* world,
                                           int32_t world_capacity)
{
    return jointPoses("chaintube_rig_joint_poses", rig, hose, local, local_capacity, world,
                      world_capacity);
}

chaintube_status chaintube_rig_joint_poses_f64(const chaintube_rig* rig, int32_t hose,
                                               double* local, int32_t local_capacity, double* world,
                                               int32_t world_capacity)
{
    return jointPoses("chaintube_rig_joint_poses_f64", rig, hose, local, local_capacity, world,
                      world_capacity);
}

chaintube_status chaintube_rig_surface(const chaintube_rig* rig, int32_t hose, float* positions,
                                       int32_t positions_capacity, float* normals,
                                       int32_t normals_capacity)
{
    constexpr const char* function = "chaintube_rig_surface";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkHose(function, rig, hose)) return status;
        const chaintube::HoseSurface& surface = rig->runtime.surface(hose);
        const size_t floats = 3 * surface.vertexCount();
        if (const chaintube_status status = checkOutputs(
                function, positions, "positions", positions_capacity, floats, normals, "normals",
                normals_capacity, floats,
                hoseName(rig, hose) + " with " + std::to_string(surface.vertexCount()) +
                    " vertices (3 floats each)"))
            return status;
        if (positions) {
            // As HoseRuntime::worldPositions, without its allocation: the origin added in double.
            const std::span<const float> local = surface.positions();
            const chaintube::Vec3& origin = rig->runtime.hose(hose).origin();
            for (size_t v = 0; v < floats; v += 3)
                for (size_t c = 0; c < 3; ++c)
                    positions[v + c] = static_cast<float>(static_cast<double>(local[v + c]) +
                                                          origin(static_cast<Eigen::Index>(c)));
        }
        if (normals) {
            const std::span<const float> unit = surface.normals();
            std::copy(unit.begin(), unit.end(), normals);
        }
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_surface_topology(const chaintube_rig* rig, int32_t hose,
                                                uint32_t* indices, int32_t indices_capacity,
                                                float* uvs, int32_t uvs_capacity)
{
    constexpr const char* function = "chaintube_rig_surface_topology";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkHose(function, rig, hose)) return status;
        const chaintube::SurfaceTopology& topology = rig->runtime.surface(hose).topology();
        if (const chaintube_status status = checkOutputs(
                function, indices, "indices", indices_capacity, topology.indices.size(), uvs, "uvs",
                uvs_capacity, topology.uvs.size(),
                hoseName(rig, hose) + " with " + std::to_string(topology.indices.size()) +
                    " indices and " + std::to_string(topology.uvs.size()) + " uv floats"))
            return status;
        if (indices) std::copy(topology.indices.begin(), topology.indices.end(), indices);
        if (uvs) std::copy(topology.uvs.begin(), topology.uvs.end(), uvs);
        return CHAINTUBE_OK;
    });
}

// --- Reel in, pay out ----------------------------------------------------------------------

chaintube_status chaintube_rig_reel(chaintube_rig* rig, int32_t hose, int32_t end, int32_t clip,
                                    double length, double min_length, double max_length,
                                    chaintube_reel_result* result)
{
    constexpr const char* function = "chaintube_rig_reel";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkHose(function, rig, hose)) return status;
        if (end != 0 && end != 1)
            return fail(CHAINTUBE_ERROR_INVALID_ARGUMENT, function,
                        "end " + std::to_string(end) +
                            ": expected 0 (the first point's end) or 1 (the last point's)");
        const int clips = static_cast<int>(rig->runtime.description(hose).clips.size());
        if (clip < -1 || clip >= clips)
            return fail(CHAINTUBE_ERROR_OUT_OF_RANGE, function,
                        "clip " + std::to_string(clip) + " is out of range: expected -1 (the " +
                            "end's attachment) or a clip of " + hoseName(rig, hose) +
                            ", which has " + std::to_string(clips) + " (chaintube_rig_clip_count)");
        const chaintube::HoseEnd which =
            end == 0 ? chaintube::HoseEnd::Start : chaintube::HoseEnd::End;
        const chaintube::ReelResult outcome =
            clip < 0
                ? rig->runtime.reel(hose, which, length, min_length, max_length)
                : rig->runtime.reelThroughClip(hose, clip, which, length, min_length, max_length);
        if (outcome.status == Status::InvalidInput)
            return fail(CHAINTUBE_ERROR_INVALID_ARGUMENT, function, outcome.message);
        if (result) {
            const chaintube::Hose& running = rig->runtime.hose(hose);
            chaintube_reel_result out{};
            out.paid = outcome.paid;
            out.rest_length = running.restLengthTotal();
            out.largest_move = outcome.largestMove;
            out.message = rig->keep(outcome.message);
            out.clamped = outcome.clamped ? 1 : 0;
            out.segments_added = outcome.segmentsAdded;
            out.segments_removed = outcome.segmentsRemoved;
            out.point_count = running.pointCount();
            *result = out;
        }
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_set_budget(chaintube_rig* rig, int32_t newton_steps)
{
    constexpr const char* function = "chaintube_rig_set_budget";
    return guarded(function, [&]() -> chaintube_status {
        if (!rig) return nullArgument(function, "rig");
        if (newton_steps < 0)
            return fail(CHAINTUBE_ERROR_INVALID_ARGUMENT, function,
                        "newton_steps: expected a number of Newton steps >= 0 (0: no bound), got " +
                            std::to_string(newton_steps));
        rig->runtime.setBudget(chaintube::UpdateBudget{newton_steps});
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_axis_points(const chaintube_rig* rig, int32_t hose, double* points,
                                           int32_t capacity)
{
    constexpr const char* function = "chaintube_rig_axis_points";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkHose(function, rig, hose)) return status;
        if (!points) return nullArgument(function, "points");
        const chaintube::Hose& running = rig->runtime.hose(hose);
        const size_t count = static_cast<size_t>(running.pointCount());
        if (const chaintube_status status =
                checkCapacity(function, "points", capacity, 3 * count,
                              hoseName(rig, hose) + " with " + std::to_string(count) +
                                  " points (3 doubles each)"))
            return status;
        for (size_t i = 0; i < count; ++i) {
            const chaintube::Vec3 point = running.point(static_cast<int>(i));
            for (size_t k = 0; k < 3; ++k)
                points[3 * i + k] = point(static_cast<Eigen::Index>(k));
        }
        return CHAINTUBE_OK;
    });
}

chaintube_status chaintube_rig_hose_pending(const chaintube_rig* rig, int32_t hose,
                                            int32_t* pending, double* remaining)
{
    constexpr const char* function = "chaintube_rig_hose_pending";
    return guarded(function, [&]() -> chaintube_status {
        if (const chaintube_status status = checkHose(function, rig, hose)) return status;
        if (!pending && !remaining) return nullArgument(function, "pending and remaining");
        if (pending) *pending = rig->runtime.pending(hose) ? 1 : 0;
        if (remaining) *remaining = rig->runtime.remaining(hose);
        return CHAINTUBE_OK;
    });
}

} // extern "C"
