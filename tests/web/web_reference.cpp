// The native side of the browser tests, through the C ABI (chaintube/runtime_c.h) as the
// WebAssembly module runs it:
//
//   web_reference replay <export.glb> <inputs.json>
//       replays inputs the JavaScript API recorded (Rig.recordInputs: a JSON array of
//       {"op":"move","node","trs"}, {"op":"grab","hose","point","target"}, {"op":"release","hose"},
//       {"op":"reel","hose","end","clip","length","min","max"}, {"op":"update"[,"seconds"]},
//       {"op":"budget","newtonSteps"}) on the export loaded from the file, and prints every
//       hose's joint world positions:
//       {"hoses":[{"id":"left-feed","joints":[[x,y,z],...]},...]} (metres, %.17g).
//
//   web_reference frames <export.glb> <frames>
//       times the frame the web viewer runs (tests/clients/wasm_frame_time.mjs runs the same in
//       the browser): every hose with free points has the one nearest its middle grabbed and
//       walked, then update() and every hose's local joint poses; prints
//       {"frames":N,"grabbed":G,"medianMs":…,"meanMs":…,"checksum":…}. The walk: per hose a
//       xorshift32 generator seeded with 0x9E3779B9 ^ (hose + 1) steps each coordinate by
//       (r % 3 - 1) centimetres a frame within ±5 cm of where the point was loaded.
//
// Exit 0: done; 1: a call failed (its message printed); 2: bad command line.
#include <algorithm>
#include <chaintube/runtime_c.h>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

void check(chaintube_status status, const char* call)
{
    if (status != CHAINTUBE_OK)
        throw std::runtime_error(std::string(call) + ": " + chaintube_status_name(status) + ": " +
                                 chaintube_last_error());
}

chaintube_rig* load(const char* file)
{
    chaintube_rig* rig = nullptr;
    check(chaintube_rig_load_file(CHAINTUBE_RUNTIME_ABI_VERSION, file, &rig),
          "chaintube_rig_load_file");
    return rig;
}

int32_t hoseCount(const chaintube_rig* rig)
{
    int32_t count = 0;
    check(chaintube_rig_hose_count(rig, &count), "chaintube_rig_hose_count");
    return count;
}

chaintube_hose_info hoseInfo(const chaintube_rig* rig, int32_t hose)
{
    chaintube_hose_info info{};
    check(chaintube_rig_hose_info(rig, hose, &info), "chaintube_rig_hose_info");
    return info;
}

std::vector<double> worldPoses(const chaintube_rig* rig, int32_t hose, int32_t joints)
{
    std::vector<double> world(7 * static_cast<size_t>(joints) + 1);
    if (joints > 0)
        check(chaintube_rig_joint_poses_f64(rig, hose, nullptr, 0, world.data(), 7 * joints),
              "chaintube_rig_joint_poses_f64");
    return world;
}

int replay(const char* exportFile, const char* inputsFile)
{
    std::ifstream stream(inputsFile);
    if (!stream) throw std::runtime_error(std::string(inputsFile) + ": cannot be read");
    const nlohmann::json inputs = nlohmann::json::parse(stream);
    chaintube_rig* rig = load(exportFile);
    for (const nlohmann::json& input : inputs) {
        const std::string op = input.at("op").get<std::string>();
        if (op == "move") {
            const std::vector<double> trs = input.at("trs").get<std::vector<double>>();
            if (trs.size() != 10) throw std::runtime_error("move: expected 10 numbers in trs");
            check(
                chaintube_rig_set_node_transform(rig, input.at("node").get<int32_t>(), trs.data()),
                "chaintube_rig_set_node_transform");
        } else if (op == "grab") {
            const std::vector<double> target = input.at("target").get<std::vector<double>>();
            if (target.size() != 3) throw std::runtime_error("grab: expected 3 numbers in target");
            check(chaintube_rig_grab(rig, input.at("hose").get<int32_t>(),
                                     input.at("point").get<int32_t>(), target.data(), nullptr),
                  "chaintube_rig_grab");
        } else if (op == "release") {
            check(chaintube_rig_release(rig, input.at("hose").get<int32_t>()),
                  "chaintube_rig_release");
        } else if (op == "plug") {
            check(chaintube_rig_plug(rig, input.at("hose").get<int32_t>(),
                                     input.at("end").get<int32_t>(),
                                     input.at("socket").get<int32_t>(), nullptr),
                  "chaintube_rig_plug");
        } else if (op == "unplug") {
            check(chaintube_rig_unplug(rig, input.at("hose").get<int32_t>(),
                                       input.at("end").get<int32_t>(), nullptr),
                  "chaintube_rig_unplug");
        } else if (op == "reel") {
            const auto bound = [&](const char* key) {
                const nlohmann::json& value = input.at(key);
                return value.is_null() ? HUGE_VAL : value.get<double>(); // JSON has no Infinity
            };
            check(chaintube_rig_reel(
                      rig, input.at("hose").get<int32_t>(), input.at("end").get<int32_t>(),
                      input.at("clip").get<int32_t>(), input.at("length").get<double>(),
                      bound("min"), bound("max"), nullptr),
                  "chaintube_rig_reel");
        } else if (op == "update" && input.contains("seconds")) {
            check(chaintube_rig_update_seconds(rig, input.at("seconds").get<double>(), nullptr),
                  "chaintube_rig_update_seconds");
        } else if (op == "update") {
            check(chaintube_rig_update(rig, nullptr), "chaintube_rig_update");
        } else if (op == "budget") {
            check(chaintube_rig_set_budget(rig, input.at("newtonSteps").get<int32_t>()),
                  "chaintube_rig_set_budget");
        } else {
            throw std::runtime_error("unknown input op \"" + op + "\"");
        }
    }
    std::string out = "{\"hoses\":[";
    char number[64];
    for (int32_t h = 0, count = hoseCount(rig); h < count; ++h) {
        const chaintube_hose_info info = hoseInfo(rig, h);
        const std::vector<double> world = worldPoses(rig, h, info.joint_count);
        out += std::string(h ? "," : "") + "{\"id\":" + nlohmann::json(info.id).dump() +
               ",\"joints\":[";
        for (int32_t j = 0; j < info.joint_count; ++j) {
            out += j ? ",[" : "[";
            for (int k = 0; k < 3; ++k) {
                std::snprintf(number, sizeof number, "%s%.17g", k ? "," : "", world[7 * j + k]);
                out += number;
            }
            out += "]";
        }
        out += "]}";
    }
    out += "]}\n";
    std::fputs(out.c_str(), stdout);
    chaintube_rig_destroy(rig);
    return 0;
}

struct Walk
{
    int32_t hose = 0, point = 0;
    double laid[3] = {0, 0, 0};
    int offset[3] = {0, 0, 0}; // centimetres, -5..5
    uint32_t state = 0;

    uint32_t next()
    {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        return state;
    }

    void step(double target[3])
    {
        for (int c = 0; c < 3; ++c) {
            offset[c] = std::clamp(offset[c] + static_cast<int>(next() % 3) - 1, -5, 5);
            target[c] = laid[c] + offset[c] * 0.01;
        }
    }
};

int frames(const char* exportFile, int frameCount)
{
    chaintube_rig* rig = load(exportFile);
    const int32_t hoses = hoseCount(rig);
    std::vector<Walk> walks;
    std::vector<std::vector<float>> local(static_cast<size_t>(hoses));
    std::vector<int32_t> jointCounts(static_cast<size_t>(hoses));
    for (int32_t h = 0; h < hoses; ++h) {
        const chaintube_hose_info info = hoseInfo(rig, h);
        jointCounts[static_cast<size_t>(h)] = info.joint_count;
        local[static_cast<size_t>(h)].resize(10 * static_cast<size_t>(info.joint_count) + 1);
        if (info.grabbable_count == 0) continue;
        std::vector<int32_t> points(static_cast<size_t>(info.grabbable_count));
        check(chaintube_rig_grabbable_points(rig, h, points.data(), info.grabbable_count),
              "chaintube_rig_grabbable_points");
        const int32_t middle = info.point_count / 2;
        Walk walk;
        walk.hose = h;
        walk.point =
            *std::min_element(points.begin(), points.end(), [middle](int32_t a, int32_t b) {
                return std::abs(a - middle) < std::abs(b - middle);
            });
        const std::vector<double> world = worldPoses(rig, h, info.joint_count);
        for (int c = 0; c < 3; ++c)
            walk.laid[c] = world[7 * static_cast<size_t>(walk.point) + static_cast<size_t>(c)];
        walk.state = 0x9E3779B9u ^ static_cast<uint32_t>(h + 1);
        walks.push_back(walk);
    }
    std::vector<double> milliseconds;
    double checksum = 0.0;
    for (int f = 0; f < frameCount; ++f) {
        const auto start = std::chrono::steady_clock::now();
        for (Walk& walk : walks) {
            double target[3];
            walk.step(target);
            check(chaintube_rig_grab(rig, walk.hose, walk.point, target, nullptr),
                  "chaintube_rig_grab");
        }
        check(chaintube_rig_update(rig, nullptr), "chaintube_rig_update");
        for (int32_t h = 0; h < hoses; ++h) {
            const int32_t joints = jointCounts[static_cast<size_t>(h)];
            if (joints > 0)
                check(chaintube_rig_joint_poses(rig, h, local[static_cast<size_t>(h)].data(),
                                                10 * joints, nullptr, 0),
                      "chaintube_rig_joint_poses");
        }
        const auto stop = std::chrono::steady_clock::now();
        milliseconds.push_back(std::chrono::duration<double, std::milli>(stop - start).count());
        for (const std::vector<float>& poses : local)
            checksum += poses[0];
    }
    double mean = 0.0;
    for (double ms : milliseconds)
        mean += ms / static_cast<double>(milliseconds.size());
    std::vector<double> sorted = milliseconds;
    std::sort(sorted.begin(), sorted.end());
    const double median = sorted.empty() ? 0.0 : sorted[sorted.size() / 2];
    std::printf(
        "{\"frames\":%d,\"grabbed\":%zu,\"medianMs\":%.4f,\"meanMs\":%.4f,\"checksum\":%.9g}\n",
        frameCount, walks.size(), median, mean, checksum);
    chaintube_rig_destroy(rig);
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    const std::string mode = argc > 1 ? argv[1] : "";
    if (argc != 4 || (mode != "replay" && mode != "frames")) {
        std::fprintf(stderr, "usage: web_reference replay <export.glb> <inputs.json>\n"
                             "       web_reference frames <export.glb> <frames>\n");
        return 2;
    }
    try {
        return mode == "replay" ? replay(argv[2], argv[3]) : frames(argv[2], std::atoi(argv[3]));
    } catch (const std::exception& error) {
        std::fprintf(stderr, "web_reference: %s\n", error.what());
        return 1;
    }
}
