// The runtime descriptor: exact round trip, and malformed documents rejected with a pointer.
#include "export_test_support.h"

#include <algorithm>
#include <chaintube/export/rig_descriptor.h>
#include <chaintube/export/runtime.h>

namespace chaintube::exporting::testing {
namespace {

rig::HoseRigDescriptor exportedDescriptor(const std::string& sample)
{
    TemporaryFolder folder;
    return exportProjectFile(samplesDir() / (sample + ".ctproj"), folder / "out.glb", roots())
        .descriptor;
}

/// Parses `text` and returns the DescriptorError's pointer ("(parsed)" if it parsed).
std::string pointerOfError(const std::string& text)
{
    try {
        rig::parseDescriptor(text, "test.hoses.json");
    } catch (const rig::DescriptorError& error) {
        EXPECT_NE(std::string(error.what()).find("test.hoses.json"), std::string::npos);
        return error.pointer();
    }
    return "(parsed)";
}

TEST(RigDescriptor, SerialiseThenParseGivesBackTheSameDescriptor)
{
    const rig::HoseRigDescriptor descriptor = exportedDescriptor("test-rig");
    const std::string text = rig::serialiseDescriptor(descriptor);
    const rig::HoseRigDescriptor parsed = rig::parseDescriptor(text, "x");
    EXPECT_EQ(rig::serialiseDescriptor(parsed), text);
    ASSERT_EQ(parsed.hoses.size(), 2u);
    // Full double precision: the axis and rest lengths read back equal the exported ones.
    EXPECT_EQ(parsed.hoses[0].axis, descriptor.hoses[0].axis);
    EXPECT_EQ(parsed.hoses[0].restLengths, descriptor.hoses[0].restLengths);
    EXPECT_TRUE(rig::withinStretchBand(parsed.hoses[0]));
}

TEST(RigDescriptor, AHoseExportedAwayFromItsRestShapeComesBackWithItsRestLengths)
{
    rig::HoseRigDescriptor descriptor = exportedDescriptor("test-rig");
    rig::RigHose& hose = descriptor.hoses[0];
    // Stretch the exported axis by 1 % about its first point (within the material's band).
    const std::vector<Vec3> exported = hose.axis;
    const Vec3 first = hose.axis.front();
    for (Vec3& point : hose.axis)
        point = first + 1.01 * (point - first);
    EXPECT_FALSE(rig::restLengthsMatch(hose));
    const Hose rebuilt = rig::rebuildHose(hose);
    ASSERT_EQ(rebuilt.pointCount(), static_cast<int>(hose.axis.size()));
    for (int s = 0; s + 1 < rebuilt.pointCount(); ++s) {
        EXPECT_EQ(rebuilt.restLength(s), hose.restLengths[static_cast<size_t>(s)]) << s;
        EXPECT_NEAR(
            (rebuilt.point(s + 1) - rebuilt.point(s)).norm(),
            1.01 * (exported[static_cast<size_t>(s) + 1] - exported[static_cast<size_t>(s)]).norm(),
            1e-9)
            << s;
    }
}

TEST(RigDescriptor, EveryCrossSectionShapeRebuildsTheSameProfile)
{
    const std::vector<Profile> profiles{
        Profile::circle(0.01, 12), Profile::ellipse(0.01, 0.006, 10),
        Profile::rectangle(0.02, 0.01), Profile::roundedRectangle(0.02, 0.01, 0.002, 3),
        Profile::polygon({{0.0, 0.0}, {0.02, 0.0}, {0.0, 0.015}}, 0.1)};
    for (const Profile& profile : profiles) {
        const Profile rebuilt = rig::CrossSection::of(profile).build();
        EXPECT_TRUE(rebuilt == profile);
        EXPECT_EQ(rebuilt.points(), profile.points());
    }
}

TEST(RigDescriptor, RejectsMalformedDocumentsNamingTheField)
{
    const Json good = Json::parse(rig::serialiseDescriptor(exportedDescriptor("test-rig")));
    EXPECT_EQ(pointerOfError(good.dump()), "(parsed)");

    Json bad = good;
    bad["hoses"][0]["attachments"] = nullptr; // what tinygltf would have written for []
    EXPECT_EQ(pointerOfError(bad.dump()), "/hoses/0/attachments");

    bad = good;
    bad["hoses"][0]["restLengths"].erase(0);
    EXPECT_EQ(pointerOfError(bad.dump()), "/hoses/0/restLengths");

    bad = good;
    bad["hoses"][1]["attachments"][1]["points"] = Json::array({0, 3}); // overlaps attachment 0
    EXPECT_EQ(pointerOfError(bad.dump()), "/hoses/1/attachments/1/points");

    bad = good;
    bad["hoses"][0]["grabbablePoints"][0] = 0; // point 0 is attached
    EXPECT_EQ(pointerOfError(bad.dump()), "/hoses/0/grabbablePoints/0");

    bad = good;
    bad["hoses"][0]["attachments"][0]["offset"]["rotation"] = Json::array({0, 0, 0, 2});
    EXPECT_EQ(pointerOfError(bad.dump()), "/hoses/0/attachments/0/offset/rotation");

    bad = good;
    bad["version"] = "2.0";
    EXPECT_EQ(pointerOfError(bad.dump()), "/version");

    bad = good;
    bad["hoses"][0]["expansionCoefficient"] = 1.5;
    EXPECT_EQ(pointerOfError(bad.dump()), "/hoses/0/expansionCoefficient");

    bad = good;
    bad["hoses"][1]["id"] = good["hoses"][0]["id"];
    EXPECT_EQ(pointerOfError(bad.dump()), "/hoses/1/id");

    EXPECT_EQ(pointerOfError("{ not json"), "");
}

TEST(RigDescriptor, AStaticHoseMustBeAPlainMeshWithEveryPointFixedToOneNode)
{
    TemporaryFolder folder;
    const rig::HoseRigDescriptor descriptor =
        exportProjectFile(testDataDir() / "rig-options.ctproj", folder / "o.glb", roots())
            .descriptor;
    const Json good = Json::parse(rig::serialiseDescriptor(descriptor));
    ASSERT_EQ(good["hoses"][0]["id"], "pipe-on-plate");
    ASSERT_EQ(good["hoses"][0]["static"], true);
    EXPECT_EQ(pointerOfError(good.dump()), "(parsed)");

    Json bad = good;
    bad["hoses"][1]["static"] = true; // valve-tail is skinned and has free points
    EXPECT_EQ(pointerOfError(bad.dump()), "/hoses/1/skin");

    bad = good;
    bad["hoses"][0]["static"] = "yes";
    EXPECT_EQ(pointerOfError(bad.dump()), "/hoses/0/static");

    bad = good;
    bad["hoses"][0]["attachments"][0]["points"][1] = 3; // points 4 … 8 no longer fixed
    EXPECT_EQ(pointerOfError(bad.dump()), "/hoses/0/static");

    // Version 1.0 documents have no "static": read as skinned.
    bad = good;
    bad["version"] = "1.0";
    bad["hoses"][1].erase("static");
    EXPECT_EQ(pointerOfError(bad.dump()), "(parsed)");
}

TEST(RigDescriptor, GravityTorsionAndCollidersRoundTripAndReachTheRebuiltHose)
{
    rig::HoseRigDescriptor descriptor = exportedDescriptor("test-rig");
    descriptor.hoses[0].gravity = {true, Vec3(0.1, -2.0, 0.0)};
    descriptor.hoses[1].torsion = {true, 0.25};
    descriptor.colliders = {1, 3};
    const std::string text = rig::serialiseDescriptor(descriptor);
    const rig::HoseRigDescriptor parsed = rig::parseDescriptor(text, "x");
    EXPECT_EQ(rig::serialiseDescriptor(parsed), text);
    EXPECT_TRUE(parsed.hoses[0].gravity.enabled);
    EXPECT_EQ(parsed.hoses[0].gravity.direction, Vec3(0.1, -2.0, 0.0));
    EXPECT_FALSE(parsed.hoses[0].torsion.enabled);
    EXPECT_TRUE(parsed.hoses[1].torsion.enabled);
    EXPECT_EQ(parsed.hoses[1].torsion.twistLimit, 0.25);
    EXPECT_EQ(parsed.colliders, (std::vector<int>{1, 3}));
    const Hose rebuilt = rig::rebuildHose(parsed.hoses[0]);
    EXPECT_TRUE(rebuilt.spec().gravity.enabled);
    EXPECT_EQ(rebuilt.spec().gravity.direction, Vec3(0.1, -2.0, 0.0));
    EXPECT_EQ(rig::rebuildHose(parsed.hoses[1]).spec().torsion.twistLimit, 0.25);

    // Bad values name the member.
    const Json good = Json::parse(text);
    Json bad = good;
    bad["hoses"][0]["gravity"]["direction"] = Json::array({0, 0, 0});
    EXPECT_EQ(pointerOfError(bad.dump()), "/hoses/0/gravity/direction");
    bad = good;
    bad["hoses"][0]["gravity"]["enabled"] = 1;
    EXPECT_EQ(pointerOfError(bad.dump()), "/hoses/0/gravity/enabled");
    bad = good;
    bad["hoses"][0]["gravity"]["strength"] = 9.81;
    EXPECT_EQ(pointerOfError(bad.dump()), "/hoses/0/gravity/strength");
    bad = good;
    bad["hoses"][1]["torsion"]["twistLimit"] = 0;
    EXPECT_EQ(pointerOfError(bad.dump()), "/hoses/1/torsion/twistLimit");
    bad = good;
    bad["hoses"][1]["torsion"]["twistLimit"] = 4.0;
    EXPECT_EQ(pointerOfError(bad.dump()), "/hoses/1/torsion/twistLimit");
    bad = good;
    bad["hoses"][1]["torsion"].erase("enabled");
    EXPECT_EQ(pointerOfError(bad.dump()), "/hoses/1/torsion/enabled");
    bad = good;
    bad["colliders"] = Json::array({3, 1});
    EXPECT_EQ(pointerOfError(bad.dump()), "/colliders/1");
    bad = good;
    bad["colliders"] = Json::array({-1});
    EXPECT_EQ(pointerOfError(bad.dump()), "/colliders/0");
    // Collider nodes must exist in the glTF.
    EXPECT_FALSE(rig::checkAgainstGltf(parsed, 3, 2).empty());

    // A 1.1 document (no gravity, torsion, colliders) reads with all of them off.
    bad = good;
    bad["version"] = "1.1";
    bad.erase("colliders");
    bad["hoses"][0].erase("gravity");
    bad["hoses"][1].erase("torsion");
    const rig::HoseRigDescriptor old = rig::parseDescriptor(bad.dump(), "old");
    EXPECT_FALSE(old.hoses[0].gravity.enabled);
    EXPECT_FALSE(old.hoses[1].torsion.enabled);
    EXPECT_TRUE(old.colliders.empty());
}

TEST(RigDescriptor, MotionsReachTheDescriptorWithTheirGltfNodesAndRoundTrip)
{
    // samples/motion-rig.ctproj: a lever on a hinge and a carriage on a slider.
    TemporaryFolder folder;
    const ExportReport report =
        exportProjectFile(samplesDir() / "motion-rig.ctproj", folder / "out.glb", roots());
    const rig::HoseRigDescriptor& descriptor = report.descriptor;
    ASSERT_EQ(descriptor.motions.size(), 2u);
    const rig::HoseRuntime runtime = rig::HoseRuntime::load(folder / "out.glb");
    ASSERT_EQ(runtime.descriptor().motions.size(), 2u);
    const rig::RigMotion& lever = runtime.descriptor().motions[0];
    EXPECT_EQ(lever.id, "lever");
    EXPECT_EQ(lever.kind, rig::RigMotion::Kind::Hinge);
    EXPECT_EQ(runtime.node(lever.node).name, "lever");
    EXPECT_EQ(lever.axis, Vec3(0.0, 0.0, 1.0));
    EXPECT_EQ(lever.point, Vec3(0.1, 0.2, 0.0));
    EXPECT_EQ(lever.minimum, -0.5);
    EXPECT_EQ(lever.maximum, 0.8);
    const rig::RigMotion& carriage = runtime.descriptor().motions[1];
    EXPECT_EQ(carriage.id, "carriage");
    EXPECT_EQ(carriage.kind, rig::RigMotion::Kind::Slider);
    EXPECT_EQ(runtime.node(carriage.node).name, "carriage");
    EXPECT_EQ(carriage.axis, Vec3(1.0, 0.0, 0.0));
    EXPECT_EQ(carriage.minimum, -0.05);
    EXPECT_EQ(carriage.maximum, 0.05);
    EXPECT_NE(lever.node, carriage.node);

    const std::string text = rig::serialiseDescriptor(descriptor);
    const rig::HoseRigDescriptor parsed = rig::parseDescriptor(text, "x");
    EXPECT_EQ(rig::serialiseDescriptor(parsed), text);
    EXPECT_EQ(parsed.version, "1.5");

    // Bad values name the member.
    const Json good = Json::parse(text);
    ASSERT_FALSE(good["motions"][1].contains("point")); // a slider has none
    Json bad = good;
    bad["motions"][0]["kind"] = "crank";
    EXPECT_EQ(pointerOfError(bad.dump()), "/motions/0/kind");
    bad = good;
    bad["motions"][0]["axis"] = Json::array({0, 0, 2});
    EXPECT_EQ(pointerOfError(bad.dump()), "/motions/0/axis");
    bad = good;
    bad["motions"][0].erase("point");
    EXPECT_EQ(pointerOfError(bad.dump()), "/motions/0/point");
    bad = good;
    bad["motions"][1]["point"] = Json::array({0, 0, 0});
    EXPECT_EQ(pointerOfError(bad.dump()), "/motions/1/point");
    bad = good;
    bad["motions"][0]["min"] = 0.1; // the exported pose (0) must lie in the range
    EXPECT_EQ(pointerOfError(bad.dump()), "/motions/0/min");
    bad = good;
    bad["motions"][0]["max"] = 7.0; // beyond a full turn
    EXPECT_EQ(pointerOfError(bad.dump()), "/motions/0/max");
    bad = good;
    bad["motions"][1]["min"] = 0.0;
    bad["motions"][1]["max"] = 0.0; // an empty range
    EXPECT_EQ(pointerOfError(bad.dump()), "/motions/1/max");
    bad = good;
    bad["motions"][1]["id"] = "lever";
    EXPECT_EQ(pointerOfError(bad.dump()), "/motions/1/id");
    bad = good;
    bad["motions"][0]["node"] = -2;
    EXPECT_EQ(pointerOfError(bad.dump()), "/motions/0/node");
    // A motion's node must exist in the glTF.
    const std::vector<std::string> problems =
        rig::checkAgainstGltf(parsed, std::max(lever.node, carriage.node), 100);
    ASSERT_FALSE(problems.empty());
    EXPECT_NE(problems.back().find("/motions/"), std::string::npos) << problems.back();

    // A 1.2 document has no motions.
    bad = good;
    bad["version"] = "1.2";
    bad.erase("motions");
    EXPECT_TRUE(rig::parseDescriptor(bad.dump(), "old").motions.empty());
}

TEST(RigDescriptor, NodeIndicesOutsideTheGltfAreReported)
{
    const rig::HoseRigDescriptor descriptor = exportedDescriptor("test-rig");
    EXPECT_TRUE(rig::checkAgainstGltf(descriptor, 1000, 2).empty());
    const std::vector<std::string> problems = rig::checkAgainstGltf(descriptor, 10, 2);
    ASSERT_FALSE(problems.empty());
    EXPECT_NE(problems.front().find("/hoses/0/"), std::string::npos) << problems.front();
}

} // namespace
} // namespace chaintube::exporting::testing
