// Pose overrides (project format 1.1, "poses"): scene parts the author moved or rotated are
// saved per node path, read back exactly, migrated from 1.0, refused with precise errors when
// malformed, and the hoses built from a posed project follow the moved parts.
#include "chaintube/formats/project.h"
#include "chaintube/formats/project_hoses.h"
#include "test_files.h"

#include <Eigen/Geometry>
#include <cmath>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace chaintube::formats {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

const fs::path kSamples = CHAINTUBE_SAMPLES_DIR;
const std::string kCurrentVersion =
    std::to_string(kProjectFormatMajor) + "." + std::to_string(kProjectFormatMinor);

/// A rigid transform: rotation by `angle` about `axis`, then translation.
Mat4 rigid(const Vec3& axis, double angle, const Vec3& translation)
{
    Mat4 m = Mat4::Identity();
    m.topLeftCorner<3, 3>() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
    m.topRightCorner<3, 1>() = translation;
    return m;
}

Project rigWithValvePose(const ImportedScenes& scenes, const Mat4& valveMotion)
{
    Project project = loadProject(kSamples / "test-rig.ctproj");
    const ImportedScene& rig = scenes.at("rig");
    const int valve = rig.findNode("/test-rig/valve");
    EXPECT_GE(valve, 0);
    project.poses.push_back({"rig", "/test-rig/valve",
                             rig.nodes[static_cast<size_t>(valve)].localTransform * valveMotion});
    return project;
}

std::string poseError(const json& document)
{
    try {
        parseProject(document.dump(), "posed.ctproj");
    } catch (const ProjectFormatError& error) {
        return error.what();
    }
    ADD_FAILURE() << "accepted: " << document.dump();
    return {};
}

json posedJson()
{
    json document = json::parse(testing::readText(kSamples / "test-rig.ctproj"));
    json matrix = json::array();
    for (int k = 0; k < 16; ++k)
        matrix.push_back(k % 5 == 0 ? 1.0 : 0.0);
    matrix[12] = 0.25;
    document["poses"] =
        json::array({{{"scene", "rig"}, {"node", "/test-rig/valve"}, {"matrix", matrix}}});
    return document;
}

TEST(NodePoses, SaveThenLoadIsExactAndLoadThenSaveIsByteForByte)
{
    const fs::path file = kSamples / "test-rig.ctproj";
    const ImportedScenes scenes = importProjectScenes(loadProject(file), file, {});
    // Awkward doubles (rotation by 0.3 rad about a skew axis) must survive exactly.
    const Project project =
        rigWithValvePose(scenes, rigid({1, 2, 3}, 0.3, {0.011, -0.0203, 0.1 / 3}));
    testing::TemporaryFolder folder;
    fs::create_directories(folder / "scenes");
    fs::copy(kSamples / "scenes", folder / "scenes", fs::copy_options::recursive);
    const fs::path copy = folder / "posed.ctproj";
    saveProject(project, copy);
    const std::string text = testing::readText(copy);
    EXPECT_NE(text.find("\"poses\": ["), std::string::npos);
    ProjectLoadReport report;
    const Project reread = loadProject(copy, {}, &report);
    EXPECT_EQ(reread, project);
    EXPECT_FALSE(report.migrated);
    EXPECT_EQ(report.fileVersion, kCurrentVersion);
    EXPECT_EQ(serialiseProject(reread), text) << "load → save must give the same bytes";
}

TEST(NodePoses, Version1_0FilesHaveNoPosesAndAreMigrated)
{
    json document = json::parse(testing::readText(kSamples / "test-rig.ctproj"));
    document.erase("poses");
    document["version"] = "1.0";
    ProjectLoadReport report;
    const Project project = parseProject(document.dump(2), kSamples / "old.ctproj", {}, &report);
    EXPECT_TRUE(report.migrated);
    EXPECT_EQ(report.fileVersion, "1.0");
    EXPECT_TRUE(project.poses.empty());
    const json saved = json::parse(serialiseProject(project));
    EXPECT_EQ(saved["version"], kCurrentVersion);
    EXPECT_EQ(saved["poses"], json::array());
    EXPECT_EQ(project, loadProject(kSamples / "test-rig.ctproj"));
}

TEST(NodePoses, MalformedPosesNameThePointerAndTheExpectation)
{
    EXPECT_EQ(parseProject(posedJson().dump(), "posed.ctproj").poses.size(), 1u)
        << "the base document is valid";

    json unknownScene = posedJson();
    unknownScene["poses"][0]["scene"] = "engine";
    EXPECT_NE(poseError(unknownScene).find("/poses/0/scene: expected the id of a scene"),
              std::string::npos);

    json relative = posedJson();
    relative["poses"][0]["node"] = "test-rig/valve";
    EXPECT_NE(poseError(relative).find("/poses/0/node: expected a node path starting with '/'"),
              std::string::npos);

    json twice = posedJson();
    twice["poses"].push_back(twice["poses"][0]);
    EXPECT_NE(poseError(twice).find("/poses/1/node: expected one pose per node"),
              std::string::npos);

    json shortMatrix = posedJson();
    shortMatrix["poses"][0]["matrix"].erase(15);
    EXPECT_NE(poseError(shortMatrix).find("/poses/0/matrix: expected an array of exactly 16"),
              std::string::npos);

    json projective = posedJson();
    projective["poses"][0]["matrix"][3] = 0.5;
    EXPECT_NE(poseError(projective).find("/poses/0/matrix/3: expected an affine matrix"),
              std::string::npos);

    json singular = posedJson();
    singular["poses"][0]["matrix"][0] = 0.0;
    EXPECT_NE(poseError(singular).find("/poses/0/matrix: expected an invertible transform"),
              std::string::npos);

    json text = posedJson();
    text["poses"][0]["matrix"][13] = "1";
    EXPECT_NE(poseError(text).find("/poses/0/matrix/13: expected a number"), std::string::npos);

    json unknownKey = posedJson();
    unknownKey["poses"][0]["scale"] = 2;
    EXPECT_NE(poseError(unknownKey).find("/poses/0/scale: unknown key"), std::string::npos);
}

TEST(NodePoses, NonFiniteMatrixIsRefusedAtLoadAndSave)
{
    std::string text = posedJson().dump();
    const std::string needle = "0.25";
    text.replace(text.find(needle), needle.size(), "1e400");
    try {
        parseProject(text, "posed.ctproj");
        ADD_FAILURE() << "accepted 1e400";
    } catch (const ProjectFormatError&) {
    }
    Project project = parseProject(posedJson().dump(), kSamples / "posed.ctproj");
    project.poses[0].localTransform(0, 3) = std::nan("");
    testing::TemporaryFolder folder;
    EXPECT_THROW(saveProject(project, folder / "nan.ctproj"), ProjectFormatError);
    EXPECT_FALSE(fs::exists(folder / "nan.ctproj"));
}

TEST(NodePoses, BuiltHosesFollowTheMovedPartAndTheSceneCarriesThePose)
{
    const fs::path file = kSamples / "test-rig.ctproj";
    const Project filePose = loadProject(file);
    const ImportedScenes scenes = importProjectScenes(filePose, file, {});
    const Vec3 shift(0.0, 0.06, 0.04);
    const Mat4 motion = rigid({0, 1, 0}, 0.4, shift);
    const Project posed = rigWithValvePose(scenes, motion);

    const std::vector<Hose> before = buildHoses(filePose, scenes);
    const std::vector<Hose> after = buildHoses(posed, scenes);
    ASSERT_EQ(before.size(), after.size());
    const ImportedScene& rig = scenes.at("rig");
    const int valve = rig.findNode("/test-rig/valve");
    const Mat4 valveWorld = rig.worldTransform(valve);
    const Mat4 posedValveWorld = posedWorldTransform(posed, scenes, "rig", valve);
    // world ← world motion that takes every point fixed under the valve along.
    const Mat4 worldMotion = posedValveWorld * valveWorld.inverse();
    int followed = 0;
    for (size_t h = 0; h < before.size(); ++h) {
        for (const Hose::Attachment& attachment : before[h].attachments()) {
            const std::string& node =
                posed.hoses[h]
                    .attachments[static_cast<size_t>(&attachment - before[h].attachments().data())]
                    .node;
            if (node.rfind("/test-rig/valve", 0) != 0) continue;
            for (int p = attachment.first; p <= attachment.last; ++p) {
                const Vec3 expected = (worldMotion * before[h].point(p).homogeneous()).head<3>();
                EXPECT_LT((after[h].point(p) - expected).norm(), 1e-9)
                    << posed.hoses[h].id << " point " << p;
                EXPECT_GT((after[h].point(p) - before[h].point(p)).norm(), 0.03);
                ++followed;
            }
        }
    }
    EXPECT_GE(followed, 3) << "the rig has hoses fixed to the valve";
    // The same as moving the attachments of the file-pose hose (what the editor does).
    Hose manual = before[0];
    std::vector<int> ids;
    std::vector<Frame> frames;
    for (size_t a = 0; a < manual.attachments().size(); ++a) {
        const HoseAttachment& definition = posed.hoses[0].attachments[a];
        ids.push_back(manual.attachments()[a].id);
        frames.push_back(rigidPart(posedWorldTransform(posed, scenes, definition.scene,
                                                       rig.findNode(definition.node))) *
                         definition.offset);
    }
    EXPECT_NE(manual.moveAttachments(ids, frames).status, Status::InvalidInput);
    for (int p = 0; p < manual.pointCount(); ++p)
        EXPECT_EQ(manual.point(p), after[0].point(p)) << p;

    // The posed scene carries the override (what the export writes); children follow.
    const ImportedScenes moved = posedScenes(posed, scenes);
    EXPECT_EQ(moved.at("rig").nodes[static_cast<size_t>(valve)].localTransform,
              posed.poses[0].localTransform);
    const int inlet = rig.findNode("/test-rig/valve/valve_inlet");
    EXPECT_TRUE(moved.at("rig").worldTransform(inlet).isApprox(
        posedWorldTransform(posed, scenes, "rig", inlet), 1e-14));
    EXPECT_FALSE(moved.at("rig").worldTransform(inlet).isApprox(rig.worldTransform(inlet), 1e-3));
}

TEST(NodePoses, APoseOfAMissingNodeIsAnErrorNamingIt)
{
    const fs::path file = kSamples / "test-rig.ctproj";
    Project project = loadProject(file);
    const ImportedScenes scenes = importProjectScenes(project, file, {});
    project.poses.push_back({"rig", "/test-rig/no-such-part", Mat4::Identity()});
    try {
        posedScenes(project, scenes);
        ADD_FAILURE() << "accepted";
    } catch (const InvalidArgument& error) {
        EXPECT_NE(std::string(error.what()).find("/poses/0"), std::string::npos);
        EXPECT_NE(std::string(error.what()).find("/test-rig/no-such-part"), std::string::npos);
    }
    EXPECT_THROW(buildHoses(project, scenes), InvalidArgument);
}

// One rigidPart (chaintube/types.h) serves the attachments, the colliders and the runtime: its
// answer on the node transforms CAD files do contain.
TEST(NodeFrames, AMirroredNodeGivesAProperRotationFlippingItsThinnestAxis)
{
    // Scale (−1, 2, 3): x mirrored and the smallest singular value, so x is the axis flipped
    // back and the rigid part is the node's rotation itself.
    const Mat4 turn = rigid(Vec3(0, 1, 0), 0.4, Vec3(1, 2, 3));
    Mat4 mirrored = turn;
    mirrored.topLeftCorner<3, 3>() = turn.topLeftCorner<3, 3>() * Vec3(-1, 2, 3).asDiagonal();
    const Frame frame = rigidPart(mirrored);
    const Mat3 rotation = frame.rotation.toRotationMatrix();
    EXPECT_NEAR(rotation.determinant(), 1.0, 1e-12);
    EXPECT_NEAR((rotation - turn.topLeftCorner<3, 3>()).norm(), 0.0, 1e-12);
    EXPECT_EQ(frame.translation, Vec3(1, 2, 3));
}

TEST(NodeFrames, AShearedAndScaledNodeGivesTheNearestRotationIndependentOfScale)
{
    const Mat4 turn = rigid(Vec3(1, 1, 0), 0.7, Vec3(-0.5, 0.25, 4));
    Mat4 sheared = turn;
    Mat3 stretch = Mat3::Identity();
    stretch(0, 1) = 0.3; // shear x by y
    stretch(2, 2) = 25.4;
    sheared.topLeftCorner<3, 3>() = turn.topLeftCorner<3, 3>() * stretch;
    const Frame frame = rigidPart(sheared);
    const Mat3 rotation = frame.rotation.toRotationMatrix();
    EXPECT_NEAR(rotation.determinant(), 1.0, 1e-12);
    // Polar decomposition: rotation⁻¹ · block is symmetric positive definite.
    const Mat3 symmetric = rotation.transpose() * sheared.topLeftCorner<3, 3>();
    EXPECT_NEAR((symmetric - symmetric.transpose()).norm(), 0.0, 1e-9);
    EXPECT_GT(symmetric.determinant(), 0.0);
    // Scaling the whole block by 1e-6 or 1e6 (millimetres, kilometres) changes nothing.
    for (double scale : {1e-6, 1e6}) {
        Mat4 scaled = sheared;
        scaled.topLeftCorner<3, 3>() *= scale;
        EXPECT_TRUE(rigidPart(scaled).rotation.isApprox(frame.rotation, 1e-9)) << scale;
    }
}

TEST(NodeFrames, ANearSingularNodeGivesTheIdentityRotationAndNoNaN)
{
    // A part flattened to nothing along z (scale 1e-14 against 1): the relative cut (1e-12 of
    // the largest singular value) calls it degenerate; an absolute 1e-300 cut would have turned
    // rounding noise into a rotation.
    Mat4 flat = rigid(Vec3(0, 0, 1), 0.3, Vec3(0.1, 0.2, 0.3));
    flat.col(2).head<3>() *= 1e-14;
    const Frame frame = rigidPart(flat);
    EXPECT_TRUE(frame.rotation.isApprox(Quat::Identity(), 0.0));
    EXPECT_EQ(frame.translation, Vec3(0.1, 0.2, 0.3));
    // Just above the cut it is still a node with a rotation (a micrometre-thin part in metres).
    Mat4 thin = rigid(Vec3(0, 0, 1), 0.3, Vec3::Zero());
    thin.col(2).head<3>() *= 1e-9;
    EXPECT_NEAR(Eigen::AngleAxisd(Eigen::Quaterniond(rigidPart(thin).rotation)).angle(), 0.3,
                1e-12);
}

TEST(NodeFrames, ANonFiniteNodeGivesTheIdentityRotationAndAFrameTheHoseRefuses)
{
    for (double bad : {std::nan(""), HUGE_VAL}) {
        Mat4 broken = rigid(Vec3(0, 1, 0), 0.2, Vec3(1, 0, 0));
        broken(1, 1) = bad;
        const Frame frame = rigidPart(broken);
        EXPECT_TRUE(frame.rotation.coeffs().allFinite());
        EXPECT_TRUE(frame.rotation.isApprox(Quat::Identity(), 0.0)) << bad;
        EXPECT_EQ(frame.translation, Vec3(1, 0, 0));
        broken(0, 3) = bad; // a non-finite translation stays non-finite: refused downstream
        EXPECT_FALSE(isFiniteFrame(rigidPart(broken)));
        Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), 1.0, HoseSpec());
        const int id = hose.attach(0, 1, Frame::identity());
        EXPECT_EQ(hose.moveAttachment(id, rigidPart(broken)).status, Status::InvalidInput);
    }
}

} // namespace
} // namespace chaintube::formats
