// The hose's length (project format 1.3): a property of its definition, apart from its shape.
// Older files migrate to the length of the hose along their route; a route that is already a
// valid shape of the hose is its axis as it is; a longer hose gets slack between its ends.
#include "chaintube/formats/project.h"
#include "chaintube/formats/project_hoses.h"
#include "chaintube/metrics.h"
#include "chaintube/route.h"
#include "chaintube/test_support/hose_checks.h"
#include "test_files.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace chaintube::formats {
namespace {

using json = nlohmann::json;

Project sample(const std::string& name)
{
    return loadProject(test_support::sampleProject(name));
}

/// A project as a version 1.2 file would have it: no hose lengths.
std::string asVersion1_2(const Project& project)
{
    json document = json::parse(serialiseProject(project));
    document["version"] = "1.2";
    for (json& hose : document["hoses"])
        hose.erase("length");
    return document.dump();
}

using test_support::worstBandExcess;

TEST(HoseLength, AFileBefore1_3GetsTheLengthOfTheHoseAlongItsRoute)
{
    const Project rig = sample("test-rig");
    ProjectLoadReport report;
    const Project migrated =
        parseProject(asVersion1_2(rig), test_support::sampleProject("test-rig"), {}, &report);
    EXPECT_TRUE(report.migrated);
    ASSERT_EQ(migrated.hoses.size(), 2u);
    for (const HoseDefinition& hose : migrated.hoses) {
        ASSERT_TRUE(hose.length) << hose.id;
        // Its routes are axes of the hoses: as long as the route.
        EXPECT_EQ(*hose.length, polylineLength(hose.route)) << hose.id;
        HoseDefinition unset = hose;
        unset.length.reset();
        EXPECT_EQ(*hose.length, routeRestLength(migrated, unset)) << hose.id;
    }
    // The committed sample is that migration, written in the current version.
    EXPECT_EQ(migrated, rig);
    const json saved = json::parse(serialiseProject(migrated));
    EXPECT_EQ(saved["version"],
              std::to_string(kProjectFormatMajor) + "." + std::to_string(kProjectFormatMinor));
    EXPECT_EQ(saved["hoses"][1]["length"].get<double>(), *migrated.hoses[1].length);
}

TEST(HoseLength, AHoseWithoutALengthIsAsLongAsItsRouteAndWrittenWithoutOne)
{
    Project project = sample("single-hose");
    project.hoses[0].length.reset();
    const json saved = json::parse(serialiseProject(project));
    EXPECT_FALSE(saved["hoses"][0].contains("length"));
    EXPECT_EQ(parseProject(saved.dump(), "x.ctproj"), project) << "1.3 without a length stays so";
    const Hose built = buildHose(project, project.hoses[0], {});
    const Hose alongRoute =
        Hose::alongRoute(project.hoses[0].route, hoseSpecOf(project, project.hoses[0]));
    EXPECT_EQ(built.points(), alongRoute.points());
    EXPECT_EQ(built.restLengthTotal(), alongRoute.restLengthTotal());
    EXPECT_EQ(hoseLength(project, project.hoses[0]), alongRoute.restLengthTotal());
}

TEST(HoseLength, ABadLengthIsRefusedNamingItsPointer)
{
    json document = json::parse(serialiseProject(sample("test-rig")));
    document["hoses"][1]["length"] = -0.5;
    try {
        parseProject(document.dump(), "rig.ctproj");
        ADD_FAILURE() << "accepted";
    } catch (const ProjectFormatError& error) {
        EXPECT_EQ(std::string(error.what()),
                  "rig.ctproj: /hoses/1/length: expected a number in (0, inf), got -0.5");
    }
    document["hoses"][1]["length"] = "0.5 m";
    EXPECT_THROW(parseProject(document.dump(), "rig.ctproj"), ProjectFormatError);
}

TEST(HoseLength, AMigratedHoseLiesOnItsRouteAtRest)
{
    const Project rig = sample("test-rig");
    const ImportedScenes scenes =
        importProjectScenes(rig, test_support::sampleProject("test-rig"), {});
    for (const HoseDefinition& definition : rig.hoses) {
        // The sample's routes are axes of their hoses (one point per axis point): the hose is
        // that axis, every rest length its mean chord (the chords differ by what 7-decimal
        // coordinates resolve on 3 cm segments, 1e-7 m: 1e-5 of a chord).
        const Hose built = buildHose(rig, definition, scenes);
        ASSERT_EQ(built.pointCount(), int(definition.route.size())) << definition.id;
        EXPECT_EQ(*definition.length, polylineLength(definition.route));
        for (int s = 0; s < built.segmentCount(); ++s) {
            EXPECT_NEAR((built.point(s) - definition.route[size_t(s)]).norm(), 0.0, 1e-15);
            EXPECT_NEAR((built.point(s + 1) - built.point(s)).norm() / built.restLength(s), 1.0,
                        1e-5)
                << definition.id << ' ' << s;
        }
    }
    // A route that is not an axis (two points, 12 segments): laid with equal chords, at rest.
    const Project single = sample("single-hose");
    const Hose built = buildHose(single, single.hoses[0], {});
    EXPECT_NEAR(*single.hoses[0].length, 0.6, 1e-12);
    for (int s = 0; s < built.segmentCount(); ++s)
        EXPECT_NEAR((built.point(s + 1) - built.point(s)).norm(), 0.05, 1e-12) << s;
}

TEST(HoseLength, AHoseLaidAlongACurvedRouteHasEqualSegmentsAtRestWithinItsBendLimit)
{
    // Three route points with a right-angle corner: rounded with the minimum bend radius, then
    // sampled with equal chords (equal arc-length samples would be shorter on the arc).
    Project project = Project::withStandardPresets("corner");
    HoseDefinition corner;
    corner.id = "corner";
    corner.route = {Vec3(0, 0, 0), Vec3(0.5, 0, 0), Vec3(0.5, 0.5, 0)};
    corner.material = PresetName{"rubber hose"}; // minimum bend radius 0.12 m
    corner.segmentCount = 30;
    corner.length = routeRestLength(project, corner);
    const Hose hose = buildHose(project, corner, {});
    EXPECT_NEAR(hose.restLengthTotal(), *corner.length, 1e-12);
    for (int s = 0; s < hose.segmentCount(); ++s)
        EXPECT_NEAR((hose.point(s + 1) - hose.point(s)).norm(), hose.restLength(s), 1e-12) << s;
    EXPECT_NEAR((hose.point(0) - corner.route.front()).norm(), 0.0, 1e-15);
    EXPECT_NEAR((hose.points().back() - corner.route.back()).norm(), 0.0, 1e-15);
    EXPECT_FALSE(measure(hose).hasProblems());
    // Shorter than the rounded route (chords cut the arc), longer than its straight legs less
    // the whole corner.
    EXPECT_LT(*corner.length, 1.0 - (2.0 - 3.14159265358979 / 2.0) * 0.12012);
    EXPECT_GT(*corner.length, 1.0 - 2.0 * 0.12012);
}

TEST(HoseLength, ARouteThatIsAValidShapeIsTheAxisAsItIsWithTheSameRestLengths)
{
    const Project rig = sample("test-rig");
    const ImportedScenes scenes =
        importProjectScenes(rig, test_support::sampleProject("test-rig"), {});
    Hose hose = buildHose(rig, rig.hoses[0], scenes);
    std::vector<double> restBefore;
    for (int s = 0; s < hose.segmentCount(); ++s)
        restBefore.push_back(hose.restLength(s));
    // Held beyond reach for a few frames: the span goes taut, its segments stretched in their band.
    const Vec3 far = hose.point(8) + Vec3(0.0, 0.3, 0.2);
    UpdateResult pulled;
    for (int frame = 0; frame < 10; ++frame) {
        pulled = hose.grab(8, far);
        ASSERT_NE(pulled.status, Status::InvalidInput);
    }
    ASSERT_GT(hose.currentLength(), *rig.hoses[0].length * 1.001)
        << "the grab stretched it: status " << int(pulled.status) << ", grab error "
        << pulled.grabError << ", moved " << pulled.movedPoints;
    HoseDefinition reshaped = rig.hoses[0];
    reshaped.route = hose.points();
    const Hose rebuilt = buildHose(rig, reshaped, scenes);
    ASSERT_EQ(rebuilt.pointCount(), hose.pointCount());
    for (int i = 0; i < hose.pointCount(); ++i)
        EXPECT_NEAR((rebuilt.point(i) - hose.point(i)).norm(), 0.0, 1e-12) << i;
    for (int s = 0; s < hose.segmentCount(); ++s)
        EXPECT_EQ(rebuilt.restLength(s), restBefore[size_t(s)]) << s;
    EXPECT_NEAR(rebuilt.restLengthTotal(), *rig.hoses[0].length, 1e-12);
    EXPECT_LE(worstBandExcess(rebuilt), 1e-9);
}

TEST(HoseLength, ALongerHoseGetsSlackBetweenItsEndsAndDoesNotReachPastItsLastRoutePoint)
{
    const Project single = sample("single-hose"); // a free straight hose, 0.6 m, 12 segments
    const HoseDefinition& straight = single.hoses[0];
    const double length = hoseLength(single, straight);
    const HoseDefinition longer = withLength(single, straight, {}, 1.1 * length);
    EXPECT_EQ(*longer.length, 1.1 * length);
    ASSERT_EQ(longer.route.size(), 13u) << "the route is the new axis";
    EXPECT_NEAR((longer.route.front() - straight.route.front()).norm(), 0.0, 1e-12);
    EXPECT_NEAR((longer.route.back() - straight.route.back()).norm(), 0.0, 1e-12)
        << "not extended past its last route point";
    const Hose hose = buildHose(single, longer, {});
    EXPECT_EQ(hose.points(), longer.route) << "built as it lies";
    EXPECT_NEAR(hose.restLengthTotal(), 1.1 * length, 1e-12);
    // Slack, not compression: every segment at its rest length, the axis 10 % longer than the
    // straight line between the ends, so it bows away from that line.
    for (int s = 0; s < hose.segmentCount(); ++s)
        EXPECT_NEAR((hose.point(s + 1) - hose.point(s)).norm(), hose.restLength(s),
                    1e-9 * hose.restLength(s))
            << s;
    EXPECT_NEAR(hose.currentLength(), 1.1 * length, 1e-8);
    double bow = 0.0;
    for (const Vec3& point : hose.points())
        bow = std::max(bow, std::hypot(point.y() - 0.5, point.z()));
    EXPECT_GT(bow, 0.05);
    EXPECT_FALSE(measure(hose).hasProblems());
}

TEST(HoseLength, ALongerHoseFixedAtBothEndsKeepsItsFixedPointsAndEverySegmentInItsBand)
{
    const Project rig = sample("test-rig");
    const ImportedScenes scenes =
        importProjectScenes(rig, test_support::sampleProject("test-rig"), {});
    for (const HoseDefinition& definition : rig.hoses) {
        SCOPED_TRACE(definition.id);
        const Hose before = buildHose(rig, definition, scenes);
        const HoseDefinition longer =
            withLength(rig, definition, scenes, 1.05 * *definition.length);
        const Hose after = buildHose(rig, longer, scenes);
        for (int i = 0; i < after.pointCount(); ++i) {
            if (before.isFixed(i)) {
                EXPECT_NEAR((after.point(i) - before.point(i)).norm(), 0.0, 1e-9) << i;
            }
        }
        EXPECT_NEAR(after.restLengthTotal(), 1.05 * *definition.length, 1e-12);
        EXPECT_LE(worstBandExcess(after), 1e-9);
        EXPECT_GT(after.currentLength(), before.currentLength() + 0.02 * *definition.length)
            << "the added length shows";
    }
}

TEST(HoseLength, AShorterFreeHosePullsItsLastPointBackAlongTheRoute)
{
    const Project single = sample("single-hose");
    const double length = hoseLength(single, single.hoses[0]);
    const HoseDefinition shorter = withLength(single, single.hoses[0], {}, 0.5 * length);
    const Hose hose = buildHose(single, shorter, {});
    EXPECT_NEAR((hose.point(0) - single.hoses[0].route.front()).norm(), 0.0, 1e-12);
    EXPECT_NEAR(hose.currentLength(), 0.5 * length, 1e-8);
    EXPECT_NEAR(hose.point(hose.segmentCount()).x(), 0.3, 1e-6);
    EXPECT_LE(worstBandExcess(hose), 1e-9);
}

TEST(HoseLength, WithSegmentLengthTheCountFollowsAndAnEndAttachmentStaysAtTheEnd)
{
    Project rig = sample("test-rig");
    const ImportedScenes scenes =
        importProjectScenes(rig, test_support::sampleProject("test-rig"), {});
    HoseDefinition& hose = rig.hoses[0];
    hose.segmentLength = *hose.length / hose.segmentCount;
    hose.segmentCount = 0;
    const HoseDefinition longer = withLength(rig, hose, scenes, 1.25 * *hose.length);
    EXPECT_EQ(longer.route.size(), 21u); // 20 segments of the same nominal length
    ASSERT_EQ(longer.attachments.size(), 2u);
    EXPECT_EQ(longer.attachments[0].firstPoint, 0);
    EXPECT_EQ(longer.attachments[1].firstPoint, 19);
    EXPECT_EQ(longer.attachments[1].lastPoint, 20);
    const Hose built = buildHose(rig, longer, scenes);
    EXPECT_EQ(built.pointCount(), 21);
    EXPECT_LE(worstBandExcess(built), 1e-9);
    EXPECT_THROW(withLength(rig, hose, scenes, 0.0), InvalidArgument);
}

TEST(HoseLength, ClipsStayWhereTheyAreAndTheirPlacesAndEndStopsScaleWithTheLength)
{
    Project rig = sample("test-rig");
    const ImportedScenes scenes =
        importProjectScenes(rig, test_support::sampleProject("test-rig"), {});
    HoseDefinition& hose = rig.hoses[0];
    const double length = *hose.length;
    HoseClip clip;
    clip.scene = "rig";
    clip.node = "/test-rig/floor_plate";
    clip.place = 0.5 * length;
    clip.hold = Hold::SlidingTurning;
    clip.slideMin = 0.3 * length;
    clip.slideMax = 0.7 * length;
    hose.clips.push_back(clip);
    const auto clipOf = [](const Hose& built) -> const Hose::Attachment& {
        return built.attachments().back();
    };
    const Hose before = buildHose(rig, hose, scenes);
    const Vec3 centre = clipOf(before).frame.apply(clipOf(before).clipCentre);
    const Vec3 axis = clipOf(before).frame.rotation * clipOf(before).clipAxis;
    for (const double factor : {1.05, 0.99}) {
        SCOPED_TRACE(factor);
        const HoseDefinition changed = withLength(rig, hose, scenes, factor * length);
        ASSERT_EQ(changed.clips.size(), 1u);
        // Longer, the clip stays at half the length; 1 % shorter, a side comes within 0.5 % of
        // its straight line (from the end of the segment the clip holds) and the hose slides
        // through the clip to give it more.
        if (factor > 1.0) {
            EXPECT_NEAR(changed.clips[0].place, factor * 0.5 * length, 1e-12);
        } else {
            EXPECT_GT(std::abs(changed.clips[0].place - factor * 0.5 * length), 1e-4);
        }
        EXPECT_NEAR(*changed.clips[0].slideMin, factor * 0.3 * length, 1e-12);
        EXPECT_NEAR(*changed.clips[0].slideMax, factor * 0.7 * length, 1e-12);
        EXPECT_EQ(changed.clips[0].hold, Hold::SlidingTurning);
        const Hose after = buildHose(rig, changed, scenes);
        const Hose::Attachment& held = clipOf(after);
        EXPECT_NEAR((held.frame.apply(held.clipCentre) - centre).norm(), 0.0, 1e-9);
        EXPECT_NEAR((held.frame.rotation * held.clipAxis - axis).norm(), 0.0, 1e-9);
        // The hose runs through the centre along the axis.
        const Vec3 a = after.point(held.first), d = (after.point(held.last) - a).normalized();
        EXPECT_NEAR(((centre - a) - (centre - a).dot(d) * d).norm(), 0.0, 1e-9);
        EXPECT_NEAR(d.dot(axis), 1.0, 1e-9);
        EXPECT_NEAR(after.restLengthTotal(), factor * length, 1e-12);
        EXPECT_LE(worstBandExcess(after), 1e-9);
        EXPECT_FALSE(measure(after).hasProblems());
        for (int i = 0; i < after.pointCount(); ++i)
            if (before.isFixed(i) && i != clipOf(before).first && i != clipOf(before).last) {
                EXPECT_NEAR((after.point(i) - before.point(i)).norm(), 0.0, 1e-9) << i;
            }
    }
}

} // namespace
} // namespace chaintube::formats
