// Sockets through the chain: a project's sockets and plug tags are exported into the descriptor
// (1.5, "sockets", a hose's "plugs"), read back by the runtime, which lists each socket where its
// part is now; the descriptor round-trips, a 1.4 descriptor reads with none, and bad socket
// values are refused naming the member.
#include "export_test_support.h"

#include <chaintube/export/runtime.h>
#include <chaintube/formats/project_hoses.h>
#include <numbers>

namespace chaintube::exporting::testing {
namespace {

using Json = nlohmann::json;

/// The test rig with a socket on the valve and one on the floor plate, and plugs on left-feed.
formats::Project rigWithSockets(const fs::path& file)
{
    formats::Project project = loadWithRoots(file);
    formats::Socket valve;
    valve.id = "valve-port";
    valve.scene = "rig";
    valve.node = "/test-rig/valve";
    valve.position = Vec3(0.03, 0.01, -0.02);
    valve.axis = Vec3(0.0, 0.0, 2.0); // not unit: the descriptor gets it normalised
    valve.captureRadius = 0.025;
    valve.captureAngle = 0.4;
    valve.tag = "camlock";
    formats::Socket plate = valve;
    plate.id = "plate-port";
    plate.node = "/test-rig/floor_plate";
    plate.position = Vec3(0.1, 0.0, 0.05);
    plate.axis = Vec3(0.0, 1.0, 0.0);
    plate.captureAngle = std::numbers::pi;
    plate.tag = "quick-coupler";
    project.sockets = {valve, plate};
    project.hoses[0].plugs = {"quick-coupler", "camlock"};
    return project;
}

TEST(SocketExport, SocketsTravelFromTheProjectThroughTheDescriptorToTheRuntime)
{
    TemporaryFolder folder;
    const fs::path file = samplesDir() / "test-rig.ctproj";
    const formats::Project project = rigWithSockets(file);
    exportProject(project, file, folder / "sockets.glb", roots());
    rig::HoseRuntime runtime = rig::HoseRuntime::load(folder / "sockets.glb");
    EXPECT_EQ(runtime.descriptor().version, "1.5");
    ASSERT_EQ(runtime.socketCount(), 2);

    // Where the parts are in the scene the project imports (independent of the glTF).
    const formats::ImportedScenes scenes = formats::importProjectScenes(project, file, roots());
    const formats::ImportedScene& scene = scenes.at("rig");
    for (int k = 0; k < 2; ++k) {
        const formats::Socket& source = project.sockets[static_cast<size_t>(k)];
        const rig::RigSocket& described = runtime.descriptor().sockets[static_cast<size_t>(k)];
        EXPECT_EQ(described.id, source.id);
        EXPECT_EQ(described.tag, source.tag);
        EXPECT_EQ(described.captureRadius, source.captureRadius);
        EXPECT_EQ(described.captureAngle, source.captureAngle);
        const std::string name = source.node.substr(source.node.rfind('/') + 1);
        EXPECT_EQ(described.node, runtime.findNode(name));
        EXPECT_EQ(described.nodeName, name);
        EXPECT_NEAR(described.axis.norm(), 1.0, 1e-15);
        const Frame part = scene.worldFrame(scene.findNode(source.node));
        const Vec3 worldPosition = part.apply(source.position);
        const Vec3 worldAxis = part.rotation * source.axis.normalized();
        EXPECT_LE((described.worldPosition - worldPosition).norm(), 1e-12) << source.id;
        EXPECT_LE((described.worldAxis - worldAxis).norm(), 1e-12) << source.id;
        const rig::HoseRuntime::SocketPose now = runtime.socket(k);
        EXPECT_EQ(now.description, &described);
        EXPECT_LE((now.position - worldPosition).norm(), 1e-9) << source.id;
        EXPECT_LE((now.axis - worldAxis).norm(), 1e-9) << source.id;
    }
    EXPECT_EQ(runtime.findSocket("plate-port"), 1);
    EXPECT_EQ(runtime.findSocket("nowhere"), -1);
    EXPECT_THROW(runtime.socket(2), std::out_of_range);
    EXPECT_THROW(runtime.socket(-1), std::out_of_range);
    const rig::RigHose& leftFeed =
        runtime.descriptor().hoses[static_cast<size_t>(runtime.findHose("left-feed"))];
    EXPECT_EQ(leftFeed.plugStart, "quick-coupler");
    EXPECT_EQ(leftFeed.plugEnd, "camlock");
    const rig::RigHose& rightReturn =
        runtime.descriptor().hoses[static_cast<size_t>(runtime.findHose("right-return"))];
    EXPECT_TRUE(rightReturn.plugStart.empty() && rightReturn.plugEnd.empty());

    // The valve turned a quarter turn about +Y and lifted 5 cm: its socket goes with it, the
    // plate's stays.
    const int valveNode = runtime.findNode("valve");
    const Vec3 plateBefore = runtime.socket(1).position;
    const Frame valveBefore = runtime.nodeWorldFrame(valveNode);
    rig::NodeTransform local = runtime.node(valveNode).local;
    const Quat turn(Eigen::AngleAxisd(0.5 * std::numbers::pi, Vec3::UnitY()));
    local.rotation = turn * local.rotation;
    local.translation += Vec3(0.0, 0.05, 0.0);
    (void)runtime.setNodeTransform(valveNode, local);
    const Frame valveAfter = runtime.nodeWorldFrame(valveNode);
    ASSERT_GT((valveAfter.translation - valveBefore.translation).norm(), 0.04);
    const rig::RigSocket& valvePort = runtime.descriptor().sockets[0];
    const rig::HoseRuntime::SocketPose moved = runtime.socket(0);
    EXPECT_LE((moved.position - valveAfter.apply(valvePort.position)).norm(), 1e-12);
    EXPECT_LE((moved.axis - valveAfter.rotation * valvePort.axis).norm(), 1e-12);
    // The socket keeps its place on the part: same distance from the part's origin, axis turned.
    EXPECT_NEAR((moved.position - valveAfter.translation).norm(),
                (valvePort.worldPosition - valveBefore.translation).norm(), 1e-12);
    EXPECT_GT((moved.position - valvePort.worldPosition).norm(), 0.04);
    EXPECT_LE((runtime.socket(1).position - plateBefore).norm(), 1e-15);
}

TEST(SocketExport, TheTestRigSampleCarriesItsSocketsAndPlug)
{
    TemporaryFolder folder;
    const fs::path file = samplesDir() / "test-rig.ctproj";
    exportProjectFile(file, folder / "test-rig.glb", roots());
    const rig::HoseRuntime runtime = rig::HoseRuntime::load(folder / "test-rig.glb");
    ASSERT_EQ(runtime.socketCount(), 2);
    const rig::HoseRuntime::SocketPose outlet = runtime.socket(runtime.findSocket("valve-outlet"));
    EXPECT_EQ(outlet.description->node, runtime.findNode("valve"));
    EXPECT_EQ(outlet.description->tag, "camlock-19");
    // The valve sits at (0, 0.04, 0.15) turned 45° about +Y; the outlet is its -x face's centre.
    // (The scene's node transforms are imported in single precision: 1e-6.)
    const double half = std::sqrt(0.5);
    EXPECT_LE((outlet.position - Vec3(-0.04 * half, 0.04, 0.15 + 0.04 * half)).norm(), 1e-6);
    EXPECT_LE((outlet.axis - Vec3(-half, 0.0, half)).norm(), 1e-6);
    const rig::HoseRuntime::SocketPose port = runtime.socket(runtime.findSocket("plate-port"));
    EXPECT_LE((port.position - Vec3(-0.1, 0.01, -0.15)).norm(), 1e-6);
    EXPECT_EQ(
        runtime.descriptor().hoses[static_cast<size_t>(runtime.findHose("left-feed"))].plugEnd,
        "camlock-19");
}

TEST(SocketExport, TheDescriptorRoundTripsAndTheSidecarAgrees)
{
    TemporaryFolder folder;
    const fs::path file = samplesDir() / "test-rig.ctproj";
    const ExportReport report =
        exportProject(rigWithSockets(file), file, folder / "sockets.glb", roots());
    const std::string text = rig::serialiseDescriptor(report.descriptor);
    const rig::HoseRigDescriptor parsed = rig::parseDescriptor(text, "sockets.hoses.json");
    EXPECT_EQ(rig::serialiseDescriptor(parsed), text);
    ASSERT_EQ(parsed.sockets.size(), 2u);
    EXPECT_EQ(parsed.sockets[0].worldPosition, report.descriptor.sockets[0].worldPosition);
    const Json sidecar = Json::parse(readBytes(folder / "sockets.hoses.json"));
    EXPECT_EQ(sidecar["sockets"], Json::parse(text)["sockets"]);
    EXPECT_EQ(sidecar["hoses"][0]["plugs"], Json({{"start", "quick-coupler"}, {"end", "camlock"}}));
    EXPECT_FALSE(sidecar["hoses"][1].contains("plugs"));
}

TEST(SocketExport, AVersion14DescriptorReadsWithNoSockets)
{
    TemporaryFolder folder;
    const fs::path file = samplesDir() / "test-rig.ctproj";
    const ExportReport report =
        exportProject(loadWithRoots(file), file, folder / "plain.glb", roots());
    Json older = Json::parse(rig::serialiseDescriptor(report.descriptor));
    older.erase("sockets");
    older["version"] = "1.4";
    const rig::HoseRigDescriptor parsed = rig::parseDescriptor(older.dump(), "old.hoses.json");
    EXPECT_TRUE(parsed.sockets.empty());
    EXPECT_EQ(parsed.hoses.size(), report.descriptor.hoses.size());
}

TEST(SocketExport, BadSocketValuesAreRefusedNamingTheMember)
{
    TemporaryFolder folder;
    const fs::path file = samplesDir() / "test-rig.ctproj";
    const ExportReport report =
        exportProject(rigWithSockets(file), file, folder / "sockets.glb", roots());
    const Json good = Json::parse(rig::serialiseDescriptor(report.descriptor));
    struct Case
    {
        const char* member;
        Json value;
    };
    const Case cases[] = {{"captureRadius", 0.0},
                          {"captureAngle", 3.5},
                          {"captureAngle", 0.0},
                          {"axis", Json::array({0.0, 0.0, 2.0})},
                          {"worldAxis", Json::array({0.0, 0.0, 0.0})},
                          {"tag", ""},
                          {"id", "valve-port"},
                          {"node", -2},
                          {"colour", "red"}};
    for (const Case& item : cases) {
        Json bad = good;
        bad["sockets"][1][item.member] = item.value;
        try {
            rig::parseDescriptor(bad.dump(), "bad.hoses.json");
            ADD_FAILURE() << item.member << " = " << item.value.dump() << " accepted";
        } catch (const rig::DescriptorError& error) {
            EXPECT_EQ(error.pointer(), std::string("/sockets/1/") + item.member) << error.what();
            EXPECT_NE(std::string(error.what()).find("bad.hoses.json"), std::string::npos);
        }
    }
    Json badPlug = good;
    badPlug["hoses"][0]["plugs"]["middle"] = "x";
    EXPECT_THROW(rig::parseDescriptor(badPlug.dump(), "bad.hoses.json"), rig::DescriptorError);

    // A socket node outside the glTF is a problem named by its pointer.
    rig::HoseRigDescriptor outside = report.descriptor;
    outside.sockets[0].node = 100000;
    const std::vector<std::string> problems = rig::checkAgainstGltf(outside, 100, 100);
    ASSERT_FALSE(problems.empty());
    bool named = false;
    for (const std::string& problem : problems)
        named = named || problem.rfind("/sockets/0/node", 0) == 0;
    EXPECT_TRUE(named);
}

TEST(SocketExport, ASocketOnAMissingNodeFailsTheExportNamingIt)
{
    TemporaryFolder folder;
    const fs::path file = samplesDir() / "test-rig.ctproj";
    formats::Project project = rigWithSockets(file);
    project.sockets[1].node = "/test-rig/no_such_part";
    try {
        exportProject(project, file, folder / "sockets.glb", roots());
        ADD_FAILURE() << "exported";
    } catch (const InvalidArgument& error) {
        const std::string message = error.what();
        EXPECT_NE(message.find("/sockets/1/node"), std::string::npos) << message;
        EXPECT_NE(message.find("no_such_part"), std::string::npos) << message;
    }
    EXPECT_FALSE(fs::exists(folder / "sockets.glb"));
}

} // namespace
} // namespace chaintube::exporting::testing
