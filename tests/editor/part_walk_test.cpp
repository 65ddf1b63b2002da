// Part walks: every part a sample's hoses are fixed to walks along X, Y and Z and turns about
// each axis in small steps, as one drag, out and back to near where it started. After the walk
// each hose must be the hose the pose gives when typed directly (within 1 mm), inside its band,
// with no bend given way that the direct pose does not force, and undo must restore the hoses.
// With gravity on, the hoses follow the drag from their sag and are built and settled where the
// drag ends (Document::closeMerge), so the same holds for them.
#include "chaintube/editor/commands.h"
#include "chaintube/editor/document.h"
#include "chaintube/test_support/hose_checks.h"
#include "test_support.h"

#include <Eigen/Geometry>
#include <functional>
#include <gtest/gtest.h>
#include <map>
#include <memory>
#include <set>

namespace chaintube::editor {
namespace {

using test::roots;
using test::samplesDir;

std::unique_ptr<Document> openSample(const std::string& file)
{
    auto document = std::make_unique<Document>(roots());
    document->adopt(readProject(samplesDir() / file, roots()));
    return document;
}

/// The nodes the hoses' attachments and clips are on, as (scene, node index).
std::vector<NodeKey> attachedParts(const Document& document)
{
    std::set<NodeKey> parts;
    for (const formats::HoseDefinition& hose : document.project().hoses) {
        for (const formats::HoseAttachment& a : hose.attachments)
            if (const formats::ImportedScene* scene = document.scene(a.scene))
                parts.insert({a.scene, scene->findNode(a.node)});
        for (const formats::HoseClip& c : hose.clips)
            if (const formats::ImportedScene* scene = document.scene(c.scene))
                parts.insert({c.scene, scene->findNode(c.node)});
    }
    std::vector<NodeKey> out;
    for (const NodeKey& part : parts)
        if (part.second >= 0) out.push_back(part);
    return out;
}

/// A step of a walk: the part's local transform `fraction` of the way out (1 = the far end).
using Walk = std::function<formats::Mat4(const formats::Mat4& start, double fraction)>;

std::vector<std::pair<std::string, Walk>> walks()
{
    std::vector<std::pair<std::string, Walk>> all;
    for (int axis = 0; axis < 3; ++axis) {
        all.push_back({std::string("along ") + "XYZ"[axis],
                       [axis](const formats::Mat4& start, double fraction) {
                           formats::Mat4 moved = start;
                           moved(axis, 3) += 0.15 * fraction;
                           return moved;
                       }});
        all.push_back(
            {std::string("turned about ") + "XYZ"[axis],
             [axis](const formats::Mat4& start, double fraction) {
                 formats::Mat4 moved = start;
                 const Eigen::Matrix3d turn =
                     Eigen::AngleAxisd(0.6 * fraction, Vec3::Unit(axis)).toRotationMatrix();
                 moved.topLeftCorner<3, 3>() = turn * start.topLeftCorner<3, 3>();
                 return moved;
             }});
    }
    return all;
}

std::map<std::string, std::vector<Vec3>> hosePoints(const Document& document)
{
    std::map<std::string, std::vector<Vec3>> points;
    for (const formats::HoseDefinition& hose : document.project().hoses)
        if (const Hose* live = document.hose(hose.id)) points[hose.id] = live->points();
    return points;
}

double farthest(const std::vector<Vec3>& a, const std::vector<Vec3>& b)
{
    if (a.size() != b.size()) return 1e9;
    double worst = 0.0;
    for (size_t i = 0; i < a.size(); ++i)
        worst = std::max(worst, (a[i] - b[i]).norm());
    return worst;
}

/// Walks every attached part of the document out (20 steps) and back to 1/75 of the way
/// (0.15 m → 2 mm, 0.6 rad → 8 mrad) as one drag, then checks the hoses against a second
/// document given the end pose directly. Returns the number of walks made.
int walkEveryPart(Document& walked, Document& direct, const std::string& label)
{
    int count = 0;
    const std::map<std::string, std::vector<Vec3>> initial = hosePoints(walked);
    for (const NodeKey& part : attachedParts(walked)) {
        const formats::Mat4 start = walked.nodeLocalTransform(part.first, part.second);
        for (const auto& [name, walk] : walks()) {
            SCOPED_TRACE(label + ": part " + std::to_string(part.second) + " " + name);
            const int undoIndex = walked.undoStack()->index();
            walked.closeMerge();
            for (int k = 1; k <= 20; ++k)
                walked.undoStack()->push(makeSetNodeTransform(walked, part, walk(start, k / 20.0)));
            for (int k = 19; k >= 0; --k)
                walked.undoStack()->push(
                    makeSetNodeTransform(walked, part, walk(start, (k + 1.0 / 3.0) / 25.0)));
            walked.closeMerge();
            EXPECT_EQ(walked.undoStack()->index(), undoIndex + 1) << "one drag, one undo step";

            direct.closeMerge();
            direct.undoStack()->push(makeSetNodeTransform(
                direct, part, walked.nodeLocalTransform(part.first, part.second)));
            direct.closeMerge();
            for (const formats::HoseDefinition& definition : walked.project().hoses) {
                const Hose* hose = walked.hose(definition.id);
                const Hose* reference = direct.hose(definition.id);
                EXPECT_TRUE(hose && reference) << definition.id;
                if (!hose || !reference) continue;
                EXPECT_LE(test_support::worstBandExcess(*hose), 1e-6) << definition.id;
                EXPECT_LE(hose->measureViolation().angleViolation,
                          reference->measureViolation().angleViolation + 1e-9)
                    << definition.id << ": a bend the direct pose does not force stays kinked";
                EXPECT_LE(reference->measureViolation().angleViolation, 1e-9)
                    << definition.id << ": kinked 2 mm or 8 mrad from the file pose";
                EXPECT_LE(farthest(hose->points(), reference->points()), 1e-3)
                    << definition.id << ": not the shape of the direct move";
            }
            walked.undoStack()->undo();
            direct.undoStack()->undo();
            walked.closeMerge();
            for (const auto& [id, points] : initial)
                EXPECT_LE(farthest(walked.hose(id)->points(), points), 1e-3)
                    << id << ": undo does not restore the hose";
            ++count;
        }
    }
    return count;
}

TEST(DocumentPartWalks,
     EverySamplesHosesAreTheSameAfterTheirPartsWalkedOutAndBackAsWhenPlacedDirectly)
{
    // The parts: the test rig's two brackets, valve and valve inlet; the motion rig's base
    // plate, pillar, lever and carriage. The single hose is fixed to no part.
    const std::vector<std::pair<std::string, int>> samples{
        {"test-rig.ctproj", 4}, {"motion-rig.ctproj", 4}, {"single-hose.ctproj", 0}};
    for (const auto& [sample, parts] : samples) {
        auto walked = openSample(sample);
        auto direct = openSample(sample);
        walked->settleGravity();
        direct->settleGravity();
        EXPECT_EQ(walkEveryPart(*walked, *direct, sample), 6 * parts) << sample;
    }
}

TEST(DocumentPartWalks,
     TheEnginesHosesAreTheSameAfterTheirPartsWalkedOutAndBackAsWhenPlacedDirectly)
{
    if (!test::haveScenes())
        GTEST_SKIP() << "skipped: the engine scene is not in the scenes folder";
    auto walked = openSample("engine.ctproj");
    auto direct = openSample("engine.ctproj");
    walked->settleGravity();
    direct->settleGravity();
    const int parts = static_cast<int>(attachedParts(*walked).size());
    EXPECT_GE(parts, 4) << "the pistons and the body parts the hoses are fixed to";
    EXPECT_EQ(walkEveryPart(*walked, *direct, "engine.ctproj"), 6 * parts);
}

TEST(DocumentPartWalks,
     HosesWithGravityAreTheSameAfterTheirPartsWalkedOutAndBackAsWhenPlacedDirectly)
{
    auto walked = openSample("test-rig.ctproj");
    auto direct = openSample("test-rig.ctproj");
    for (Document* document : {walked.get(), direct.get()}) {
        for (const formats::HoseDefinition& hose : document->project().hoses) {
            Gravity gravity = hose.gravity;
            gravity.enabled = true;
            document->undoStack()->push(makeChangeHoseField(*document, hose.id,
                                                            &formats::HoseDefinition::gravity,
                                                            gravity, MergeId::None, "Gravity on"));
        }
        document->closeMerge();
        document->settleGravity();
        ASSERT_TRUE(document->gravityUnsettledHoses().empty());
    }
    EXPECT_GE(walkEveryPart(*walked, *direct, "test-rig with gravity"), 12);
}

TEST(DocumentPartWalks, AGravityHoseFollowsADragFromItsSagAndIsSettledWhereTheDragEnds)
{
    auto document = openSample("test-rig.ctproj");
    const std::string id = document->project().hoses[1].id; // fixed to the valve
    Gravity gravity = document->hoseDefinition(id)->gravity;
    gravity.enabled = true;
    document->undoStack()->push(makeChangeHoseField(
        *document, id, &formats::HoseDefinition::gravity, gravity, MergeId::None, "Gravity on"));
    document->closeMerge();
    document->settleGravity();
    const NodeKey valve{"rig", document->scene("rig")->findNode("/test-rig/valve")};
    const formats::Mat4 start = document->nodeLocalTransform(valve.first, valve.second);
    const double sagged = test::lowestY(document->hose(id)->points());
    formats::Mat4 moved = start;
    moved(0, 3) += 0.01;
    document->undoStack()->push(makeSetNodeTransform(*document, valve, moved));
    // During the drag: moved from the sag, not lifted back to the route.
    EXPECT_NEAR(test::lowestY(document->hose(id)->points()), sagged, 0.01);
    document->closeMerge();
    EXPECT_FALSE(document->gravityActive()) << "settled where the drag ended";
    EXPECT_NEAR(test::lowestY(document->hose(id)->points()), sagged, 0.01);
}

} // namespace
} // namespace chaintube::editor
