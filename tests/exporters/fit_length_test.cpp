// Length fitting (exporting::fitHoseLength, `chaintube check --fit-length`): analytic cases — a
// straight span, an end on a hinge, a gravity hose sagging towards a floor — and the CLI's exit
// codes and JSON on the motion-rig sample.
#include "cli_run.h"
#include "export_test_support.h"

#include <Eigen/Geometry>
#include <chaintube/export/fit_length.h>
#include <chaintube/formats/errors.h>
#include <chaintube/formats/project.h>
#include <chaintube/formats/project_hoses.h>
#include <cmath>
#include <numbers>

namespace chaintube::exporting::testing {
namespace {

struct Box
{
    const char* name;
    Vec3 lo, hi;
};

/// An OBJ with one object (a scene node under the root) per box.
void writeBoxes(const fs::path& file, const std::vector<Box>& boxes)
{
    std::ofstream out(file);
    int base = 1;
    for (const Box& b : boxes) {
        out << "o " << b.name << "\n";
        for (int i = 0; i < 8; ++i)
            out << "v " << ((i & 1) ? b.hi.x() : b.lo.x()) << " " << ((i & 2) ? b.hi.y() : b.lo.y())
                << " " << ((i & 4) ? b.hi.z() : b.lo.z()) << "\n";
        const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                 {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
        for (const auto& f : faces)
            out << "f " << base + f[0] << " " << base + f[1] << " " << base + f[2] << " "
                << base + f[3] << "\n";
        base += 8;
    }
}

/// A project of one scene of boxes and one hose from `start` to `end` (straight route, as long
/// as the route), 20 segments, 5 % stretch, 0.1 m minimum bend radius, 20 mm diameter, its end
/// points fixed to the boxes "base" and "lever" (the first two boxes).
formats::Project spanProject(const fs::path& folder, const std::vector<Box>& boxes,
                             const Vec3& start, const Vec3& end,
                             std::map<std::string, std::string>& nodes)
{
    writeBoxes(folder / "boxes.obj", boxes);
    const formats::ImportedScene imported = formats::importScene(folder / "boxes.obj", {});
    for (const Box& b : boxes)
        nodes[b.name] =
            imported.nodes[static_cast<size_t>(imported.findNodesByName(b.name).at(0))].path;
    formats::Project project = formats::Project::withStandardPresets("fit test");
    project.scenes.push_back({"boxes", "boxes.obj", {}});
    formats::HoseDefinition hose;
    hose.id = "probe";
    hose.route = {start, end};
    hose.length = (end - start).norm();
    hose.material = Material{0.05, BendLimit::minBendRadius(0.1)};
    hose.outerDiameter = 0.02;
    hose.segmentCount = 20;
    hose.attachments.push_back({"boxes", nodes.at("base"), Frame::identity(), 0, 0});
    hose.attachments.push_back({"boxes", nodes.at("lever"), Frame::identity(), 20, 20});
    project.hoses.push_back(hose);
    return project;
}

const std::vector<Box> kEnds{{"base", {-0.06, -0.03, -0.03}, {-0.02, 0.03, 0.03}},
                             {"lever", {0.96, -0.03, -0.03}, {1.04, 0.03, 0.03}}};

TEST(FitLength, AStraightSpanWithoutMotionsIsShortestAtTheSpan)
{
    // No motions: the project's pose alone. Both ends fixed 1.3 m apart; a hose of 1.5 m bows.
    // The shortest length that is never pulled taut is the span; nothing is near, so every
    // length up to the search limit keeps the clearance.
    TemporaryFolder folder;
    std::map<std::string, std::string> nodes;
    formats::Project project =
        spanProject(folder.path(), kEnds, Vec3(0, 0, 0), Vec3(1.3, 0, 0), nodes);
    project.hoses[0].route = {{0, 0, 0}, {0.65, 0.2, 0}, {1.3, 0, 0}};
    project.hoses[0].length = 1.5;
    const formats::ImportedScenes scenes =
        formats::importProjectScenes(project, folder / "p.ctproj", {});
    LengthFitOptions options;
    const LengthFit fit = fitHoseLength(project, scenes, 0, options);
    ASSERT_TRUE(fit.valid) << fit.reason;
    RecordProperty("shortest", std::to_string(fit.shortest));
    RecordProperty("longest", std::to_string(fit.longest));
    EXPECT_NEAR(fit.shortest, 1.3, options.tolerance);
    EXPECT_NEAR(fit.tautBound, 1.3, 1e-9);
    EXPECT_EQ(fit.shortestLimit, LengthLimit::Taut);
    // Nothing is near; a much longer hose ends where the re-laid shape no longer holds the
    // band (formats::withLength settles it between the held ends from the current shape).
    EXPECT_NE(fit.longestLimit, LengthLimit::Clearance);
    EXPECT_NE(fit.longestLimit, LengthLimit::Taut);
    EXPECT_GT(fit.longest, 1.5);
    EXPECT_LE(fit.longest, options.searchLimitFactor * fit.shortest);
    EXPECT_DOUBLE_EQ(fit.currentLength, 1.5);
    EXPECT_TRUE(fit.currentValid);
    EXPECT_TRUE(fit.converged);
    EXPECT_LE(fit.sweeps, options.maxSweepsPerHose);

    // A stretch allowance lets the hose be that much shorter.
    options.stretchAllowance = 0.04;
    const LengthFit allowed = fitHoseLength(project, scenes, 0, options);
    ASSERT_TRUE(allowed.valid);
    EXPECT_NEAR(allowed.shortest, 1.3 / 1.04, options.tolerance);
}

TEST(FitLength, AnEndOnAHingeNeedsTheFarthestChordOfItsCircle)
{
    // The end starts at P0 = C + (0, −R, 0) and turns about z through C = (0.8, 0, 0), R = 0.2,
    // from −0.5 to 2.5 rad: its distance from the fixed start S = 0 is
    // |C + R (sin θ, −cos θ, 0)|, at most |C| + R = 1 m (at θ = π/2, between two sweep steps).
    // The shortest length is the largest of those distances over the sweep's steps.
    TemporaryFolder folder;
    std::map<std::string, std::string> nodes;
    const Vec3 centre(0.8, 0.0, 0.0);
    const double radius = 0.2;
    const Vec3 end = centre + Vec3(0.0, -radius, 0.0);
    const std::vector<Box> boxes{{"base", {-0.06, -0.03, -0.03}, {-0.02, 0.03, 0.03}},
                                 {"lever", {0.76, -0.24, -0.03}, {0.84, -0.16, 0.03}}};
    formats::Project project = spanProject(folder.path(), boxes, Vec3::Zero(), end, nodes);
    formats::PartMotion hinge;
    hinge.id = "flap";
    hinge.scene = "boxes";
    hinge.node = nodes["lever"];
    hinge.kind = formats::PartMotion::Kind::Hinge;
    hinge.axis = Vec3::UnitZ();
    hinge.point = centre;
    hinge.minimum = -0.5;
    hinge.maximum = 2.5;
    project.motions = {hinge};
    const formats::ImportedScenes scenes =
        formats::importProjectScenes(project, folder / "p.ctproj", {});
    LengthFitOptions options;
    options.steps = 20;
    double sampled = 0.0;
    for (const SweepStep& step : sweepSchedule(project.motions, options.steps)) {
        const double angle = step.values[0];
        sampled = std::max(sampled,
                           (centre + radius * Vec3(std::sin(angle), -std::cos(angle), 0.0)).norm());
    }
    const double continuous = centre.norm() + radius;
    // Between steps (0.15 rad apart) the distance falls short of its peak by at most
    // |C| R (1 − cos 0.075) / (|C| + R).
    const double samplingError = centre.norm() * radius * (1.0 - std::cos(0.075)) / continuous;
    ASSERT_LE(continuous - sampled, samplingError);
    std::vector<double> fractions;
    options.progress = [&](double fraction) {
        fractions.push_back(fraction);
        return true;
    };
    const LengthFit fit = fitHoseLength(project, scenes, 0, options);
    ASSERT_TRUE(fit.valid) << fit.reason;
    RecordProperty("shortest", std::to_string(fit.shortest));
    RecordProperty("sampledBound", std::to_string(sampled));
    RecordProperty("continuousBound", std::to_string(continuous));
    EXPECT_NEAR(fit.shortest, sampled, options.tolerance);
    EXPECT_NEAR(fit.shortest, continuous, options.tolerance + samplingError);
    EXPECT_EQ(fit.shortestLimit, LengthLimit::Taut);
    EXPECT_FALSE(fit.currentValid) << "laid at 0.825 m, the hose cannot follow the hinge";
    EXPECT_LT(fit.currentLength, fit.shortest);
    ASSERT_FALSE(fractions.empty());
    EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
    EXPECT_LE(fractions.back(), 1.0);

    // The sweep agrees: at the shortest length nothing breaks; 5 mm below the length whose
    // stretch band just reaches the farthest chord, the hose falls short of the hinge.
    const auto sweepAt = [&](double length) {
        formats::Project single = project;
        single.hoses = {formats::withLength(project, project.hoses[0], scenes, length)};
        SweepOptions sweep;
        sweep.steps = options.steps;
        return sweepMotions(single, scenes, sweep).hoses.at(0);
    };
    EXPECT_FALSE(sweepAt(fit.shortest).violates());
    EXPECT_TRUE(sweepAt(fit.shortest / 1.05 - 0.005).beyondReach());

    // Cancel stops the search.
    options.progress = [](double fraction) { return fraction < 0.02; };
    EXPECT_THROW(fitHoseLength(project, scenes, 0, options), formats::Cancelled);
}

TEST(FitLength, AGravityHoseSaggingTowardsAFloorIsLongestAtTheCatenaryThatKeepsTheClearance)
{
    // Ends 1 m apart, 0.2 m above a floor (its top at y = 0); the hose hangs under gravity. It
    // keeps a 20 mm clearance while its lowest surface point stays 20 mm above the floor: the
    // axis sags at most 0.2 − 0.02 − 0.01 = 0.17 m. A chain of length L' sags as the catenary
    // a (cosh(s / 2a) − 1) with L' = 2 a sinh(s / 2a) (s = 1 m); the model's gravity pulls the
    // segments of a hanging hose to the end of their stretch band, so L' = 1.05 L.
    TemporaryFolder folder;
    std::map<std::string, std::string> nodes;
    const std::vector<Box> boxes{{"base", {-0.06, 0.17, -0.03}, {-0.02, 0.23, 0.03}},
                                 {"lever", {1.02, 0.17, -0.03}, {1.06, 0.23, 0.03}},
                                 {"floor", {-0.2, -0.05, -0.2}, {1.2, 0.0, 0.2}}};
    formats::Project project =
        spanProject(folder.path(), boxes, Vec3(0, 0.2, 0), Vec3(1.0, 0.2, 0), nodes);
    project.hoses[0].gravity.enabled = true;
    const formats::ImportedScenes scenes =
        formats::importProjectScenes(project, folder / "p.ctproj", {});
    LengthFitOptions options;
    options.clearanceThreshold = 0.02;
    const LengthFit fit = fitHoseLength(project, scenes, 0, options);
    ASSERT_TRUE(fit.valid) << fit.reason;
    EXPECT_NEAR(fit.shortest, 1.0, options.tolerance);
    EXPECT_FALSE(fit.longestAtSearchLimit);
    EXPECT_EQ(fit.longestLimit, LengthLimit::Clearance);
    EXPECT_NE(fit.limitingObject.find(nodes["floor"]), std::string::npos) << fit.limitingObject;
    EXPECT_LT(fit.limitingDistance, 0.02);

    const double sag = 0.2 - 0.02 - 0.01;
    double low = 0.01, high = 10.0; // a: sag falls as a grows
    for (int i = 0; i < 200; ++i) {
        const double a = 0.5 * (low + high);
        (a * (std::cosh(0.5 / a) - 1.0) > sag ? low : high) = a;
    }
    const double catenaryLength = 2.0 * low * std::sinh(0.5 / low) / 1.05;
    RecordProperty("longest", std::to_string(fit.longest));
    RecordProperty("catenaryLength", std::to_string(catenaryLength));
    // 20 straight links and a polygonal ring section against the smooth catenary: a few mm.
    EXPECT_NEAR(fit.longest, catenaryLength, 0.005)
        << "catenary " << catenaryLength << " m, fitted " << fit.longest << " m";
}

/// An axis of equal segments from A = 0 to B = (span, 0, 0) in the z = 0 plane through a clip
/// centred on `centre`: 2m segments from A to the clip's segment with slack (m at μ + δ, m at
/// μ − δ, μ the direction from A to the clip's segment), the clip's segment along x centred on
/// `centre`, then `straight` segments in a straight line to B. `segment` receives the length
/// of each.
std::vector<Vec3> routeThroughAClip(const Vec3& centre, double span, int m, int straight,
                                    double& segment)
{
    const Vec3 end(span, 0.0, 0.0);
    double l = span / (2 * m + 1 + straight);
    for (int i = 0; i < 200; ++i)
        l = (end - (centre + 0.5 * l * Vec3::UnitX())).norm() / straight;
    segment = l;
    const Vec3 entry = centre - 0.5 * l * Vec3::UnitX();
    const double mu = std::atan2(entry.y(), entry.x());
    const double delta = std::acos(entry.norm() / (2.0 * m * l));
    std::vector<Vec3> points{Vec3::Zero()};
    for (int k = 0; k < 2 * m; ++k) {
        const double a = k < m ? mu + delta : mu - delta;
        points.push_back(points.back() + l * Vec3(std::cos(a), std::sin(a), 0.0));
    }
    points.push_back(points.back() + l * Vec3::UnitX());
    const Vec3 down = (end - points.back()).normalized();
    for (int k = 0; k < straight; ++k)
        points.push_back(points.back() + l * down);
    return points;
}

/// A project of one hose along routeThroughAClip (its axis as it is: 5 % stretch, 1 rad
/// deflection limit), its end points fixed to the boxes "base" and "lever" and a sliding clip
/// on the box "guide" at the middle of the clip's segment. `segment` receives the segment
/// length.
formats::Project clipProject(const fs::path& folder, const Vec3& centre, int m, int straight,
                             std::map<std::string, std::string>& nodes, double& segment)
{
    const std::vector<Box> boxes{
        {"base", {-0.06, -0.03, -0.03}, {-0.02, 0.03, 0.03}},
        {"lever", {1.32, -0.03, -0.03}, {1.36, 0.03, 0.03}},
        {"guide", centre - Vec3(0.01, 0.03, 0.03), centre + Vec3(0.01, 0.03, 0.03)}};
    formats::Project project = spanProject(folder, boxes, Vec3::Zero(), Vec3(1.3, 0.0, 0.0), nodes);
    formats::HoseDefinition& hose = project.hoses[0];
    hose.route = routeThroughAClip(centre, 1.3, m, straight, segment);
    const int segments = static_cast<int>(hose.route.size()) - 1;
    hose.segmentCount = segments;
    hose.length = segments * segment;
    hose.material = Material{0.05, BendLimit::deflectionAngle(1.0)};
    hose.attachments[1].firstPoint = hose.attachments[1].lastPoint = segments;
    formats::HoseClip clip;
    clip.scene = "boxes";
    clip.node = nodes.at("guide");
    clip.place = (2 * m + 0.5) * segment;
    hose.clips.push_back(clip);
    return project;
}

/// The clip's centre (world) as the hose of `definition` is built, and how far the hose's axis
/// passes from it.
struct ClipAsBuilt
{
    Vec3 centre = Vec3::Zero();
    double offAxis = 0.0;
};

ClipAsBuilt clipAsBuilt(const formats::Project& project, const formats::HoseDefinition& definition,
                        const formats::ImportedScenes& scenes)
{
    const Hose hose = formats::buildHose(project, definition, scenes);
    const Hose::Attachment& clip = hose.attachments().back();
    EXPECT_TRUE(clip.isClip());
    ClipAsBuilt built;
    built.centre = clip.frame.apply(clip.clipCentre);
    const Vec3 a = hose.point(clip.first), d = (hose.point(clip.last) - a).normalized();
    const Vec3 r = built.centre - a;
    built.offAxis = (r - r.dot(d) * d).norm();
    return built;
}

TEST(FitLength, AStraightSpanThroughASlidingClipOnItsLineIsShortestAtTheSpan)
{
    // Ends 1.3 m apart, the clip's centre on the line between them at x = 0.5 with its axis
    // along it; the hose has its slack before the clip. The shortest length is the span: the
    // hose slides through the clip until both sides are straight.
    TemporaryFolder folder;
    std::map<std::string, std::string> nodes;
    double segment = 0.0;
    const formats::Project project =
        clipProject(folder.path(), Vec3(0.5, 0.0, 0.0), 4, 12, nodes, segment);
    const formats::ImportedScenes scenes =
        formats::importProjectScenes(project, folder / "p.ctproj", {});
    ASSERT_LE(clipAsBuilt(project, project.hoses[0], scenes).offAxis, 1e-12);
    LengthFitOptions options;
    const LengthFit fit = fitHoseLength(project, scenes, 0, options);
    ASSERT_TRUE(fit.valid) << fit.reason;
    RecordProperty("shortest", std::to_string(fit.shortest));
    EXPECT_NEAR(fit.tautBound, 1.3, 1e-9);
    EXPECT_GE(fit.shortest, 1.3 - 1e-9);
    EXPECT_LE(fit.shortest, 1.3 + options.tolerance);
    EXPECT_TRUE(fit.currentValid);
    EXPECT_TRUE(fit.converged);
}

TEST(FitLength, ASpanThroughAClipOffItsLineIsShortestAtTheTwoStraightDistances)
{
    // Ends A, B 1.3 m apart; the clip's centre C = (0.9, 0.1, 0) off their line, its axis along
    // x; the hose has its slack between A and the clip, and runs straight from the clip to B.
    // However the hose slides through the clip, it needs |C − A| + |B − C|: the taut bound.
    // Scaled with the length alone, the clip's place would leave the straight side short long
    // before that (it starts with 71 % of the length on A's side, where the taut hose has 69 %):
    // the hose slides through the clip instead. A chain through the clip's segment needs a
    // little more than the two distances (its segment lies along x, not along the two lines:
    // up to 1 mm here).
    TemporaryFolder folder;
    std::map<std::string, std::string> nodes;
    double segment = 0.0;
    const Vec3 centre(0.9, 0.1, 0.0);
    const formats::Project project = clipProject(folder.path(), centre, 15, 12, nodes, segment);
    const formats::ImportedScenes scenes =
        formats::importProjectScenes(project, folder / "p.ctproj", {});
    const formats::HoseDefinition& hose = project.hoses[0];
    const ClipAsBuilt built = clipAsBuilt(project, hose, scenes);
    ASSERT_LE((built.centre - centre).norm(), 1e-12);
    const Vec3 a = Vec3::Zero(), b(1.3, 0.0, 0.0);
    const double straightLines = (centre - a).norm() + (b - centre).norm();
    ASSERT_GT(hose.clips[0].place / *hose.length, (centre - a).norm() / straightLines + 0.015);
    // The chain through the clip's segment (f: where the centre is along it, as the clip's
    // place puts it), bends aside, at the segment length of the taut hose: at most this much
    // longer than the two distances.
    const double l = straightLines / hose.segmentCount;
    double excess = 0.0;
    for (int k = 0; k <= 1000; ++k) {
        const double f = k / 1000.0;
        excess = std::max(excess, (centre - f * l * Vec3::UnitX() - a).norm() + l +
                                      (b - centre - (1.0 - f) * l * Vec3::UnitX()).norm() -
                                      straightLines);
    }
    ASSERT_LT(excess, 0.002);

    LengthFitOptions options;
    options.tolerance = 0.0005;
    const LengthFit fit = fitHoseLength(project, scenes, 0, options);
    ASSERT_TRUE(fit.valid) << fit.reason;
    RecordProperty("shortest", std::to_string(fit.shortest));
    RecordProperty("straightLines", std::to_string(straightLines));
    RecordProperty("chainExcess", std::to_string(excess));
    EXPECT_NEAR(fit.tautBound, straightLines, 1e-9);
    EXPECT_GE(fit.shortest, straightLines - 1e-9);
    EXPECT_LE(fit.shortest, straightLines + excess + options.tolerance)
        << "two distances " << straightLines << " m, chain up to " << excess << " m longer";
    EXPECT_TRUE(fit.currentValid);

    // At the shortest length the hose still passes through the clip where it is, each side at
    // least its straight distance long; the clip slid towards A.
    const formats::HoseDefinition shortest =
        formats::withLength(project, hose, scenes, fit.shortest);
    const ClipAsBuilt there = clipAsBuilt(project, shortest, scenes);
    EXPECT_LE((there.centre - centre).norm(), 1e-9);
    EXPECT_LE(there.offAxis, 1e-9);
    const double place = shortest.clips[0].place;
    EXPECT_GE(place, (centre - a).norm() - 1e-9);
    EXPECT_GE(fit.shortest - place, (b - centre).norm() - 1e-9);
    EXPECT_LT(place / fit.shortest, hose.clips[0].place / *hose.length - 0.01);
    // A longer hose keeps the clip at its fraction of the length (nothing is short).
    const formats::HoseDefinition longer =
        formats::withLength(project, hose, scenes, 1.2 * *hose.length);
    EXPECT_NEAR(longer.clips[0].place, 1.2 * hose.clips[0].place, 1e-12);
    const ClipAsBuilt longerClip = clipAsBuilt(project, longer, scenes);
    EXPECT_LE((longerClip.centre - centre).norm(), 1e-9);
    EXPECT_LE(longerClip.offAxis, 1e-9);
}

TEST(FitLength, AClipOnASliderIsCarriedByTheSweep)
{
    // The clip of AStraightSpanThroughASlidingClipOnItsLine… (centre C = (0.5, 0, 0), axis x)
    // on a slider that lifts it 0.1 m along y: the path from A through the clip to B is
    // longest at the top, |C + 0.1 y − A| + |B − C − 0.1 y| = 1.3161 m, the taut bound. While
    // the clip rises the library slides the hose through it only while both sides keep 1 % of
    // their length (lib/README.md, "Clips"), so the shortest valid length is up to about 1 %
    // longer.
    TemporaryFolder folder;
    std::map<std::string, std::string> nodes;
    double segment = 0.0;
    formats::Project project =
        clipProject(folder.path(), Vec3(0.5, 0.0, 0.0), 4, 12, nodes, segment);
    formats::PartMotion lift;
    lift.id = "lift";
    lift.scene = "boxes";
    lift.node = nodes.at("guide");
    lift.kind = formats::PartMotion::Kind::Slider;
    lift.axis = Vec3::UnitY();
    lift.minimum = 0.0;
    lift.maximum = 0.1;
    project.motions = {lift};
    const formats::ImportedScenes scenes =
        formats::importProjectScenes(project, folder / "p.ctproj", {});
    const Vec3 top(0.5, 0.1, 0.0);
    const double path = top.norm() + (Vec3(1.3, 0.0, 0.0) - top).norm();
    LengthFitOptions options;
    options.steps = 10;
    const LengthFit fit = fitHoseLength(project, scenes, 0, options);
    ASSERT_TRUE(fit.valid) << fit.reason;
    RecordProperty("shortest", std::to_string(fit.shortest));
    RecordProperty("path", std::to_string(path));
    EXPECT_NEAR(fit.tautBound, path, 1e-9);
    EXPECT_GE(fit.shortest, path - 1e-9);
    EXPECT_LE(fit.shortest, path / 0.99 + options.tolerance);

    // The sweep agrees: at the shortest length the hose follows the clip to the top, through
    // its centre at every step; 1 cm shorter it has to stretch its band at the top (a chain
    // through the clip's centre is at least the path long).
    struct Swept
    {
        HoseSweep hose;
        double offAxis = 0.0, highest = -1.0;
        double pulled = -1.0; ///< largest current length − rest length (metres)
    };
    const auto sweepAt = [&](double length) {
        formats::Project single = project;
        single.hoses = {formats::withLength(project, project.hoses[0], scenes, length)};
        SweepOptions sweep;
        sweep.steps = options.steps;
        Swept swept;
        sweep.onStep = [&](int, const std::vector<Hose>& hoses) {
            const Hose& hose = hoses.front();
            const Hose::Attachment& clip = hose.attachments().back();
            const Vec3 centre = clip.frame.apply(clip.clipCentre);
            const Vec3 a = hose.point(clip.first), d = (hose.point(clip.last) - a).normalized();
            const Vec3 r = centre - a;
            swept.offAxis = std::max(swept.offAxis, (r - r.dot(d) * d).norm());
            swept.highest = std::max(swept.highest, centre.y());
            swept.pulled = std::max(swept.pulled, hose.currentLength() - hose.restLengthTotal());
        };
        swept.hose = sweepMotions(single, scenes, sweep).hoses.at(0);
        return swept;
    };
    const Swept atShortest = sweepAt(fit.shortest);
    EXPECT_FALSE(atShortest.hose.violates());
    EXPECT_NEAR(atShortest.highest, 0.1, 1e-12) << "the clip went up with the slider";
    EXPECT_LE(atShortest.offAxis, 1e-9);
    const Swept shorter = sweepAt(path - 0.01);
    EXPECT_NEAR(shorter.highest, 0.1, 1e-12);
    EXPECT_GE(shorter.pulled, 0.01 - 1e-9);
}

TEST(FitLengthCli, AHoseThroughAClipOffItsLineInJson)
{
    // The project of ASpanThroughAClipOffItsLine… saved and fitted by the CLI.
    TemporaryFolder folder;
    std::map<std::string, std::string> nodes;
    double segment = 0.0;
    const Vec3 centre(0.9, 0.1, 0.0);
    const formats::Project project = clipProject(folder.path(), centre, 15, 12, nodes, segment);
    formats::saveProject(project, folder / "clip.ctproj");
    const double straightLines = centre.norm() + (Vec3(1.3, 0.0, 0.0) - centre).norm();
    const CliRun run = runCli("check \"" + (folder / "clip.ctproj").string() +
                              "\" --fit-length --tolerance 0.0005 --json -q");
    ASSERT_EQ(run.exitCode, 0) << run.output;
    const Json report = Json::parse(run.output);
    EXPECT_EQ(report["allValid"], true);
    EXPECT_EQ(report["motions"], Json::array());
    EXPECT_EQ(report["sweptSteps"], 1);
    ASSERT_EQ(report["hoses"].size(), 1u);
    const Json& hose = report["hoses"][0];
    EXPECT_EQ(hose["id"], "probe");
    EXPECT_EQ(hose["valid"], true);
    EXPECT_NEAR(hose["length"].get<double>(), *project.hoses[0].length, 1e-12);
    EXPECT_NEAR(hose["tautBound"].get<double>(), straightLines, 1e-9);
    // Between the two straight distances and the chain through the clip's segment (1 mm more).
    EXPECT_GE(hose["shortest"].get<double>(), straightLines - 1e-9);
    EXPECT_LE(hose["shortest"].get<double>(), straightLines + 0.001 + 0.0005);
    EXPECT_GT(hose["longest"].get<double>(), hose["length"].get<double>());
    EXPECT_EQ(hose["currentValid"], true);
    EXPECT_EQ(hose["converged"], true);
    EXPECT_EQ(hose["shortestLimit"], "taut");
    EXPECT_TRUE(hose["reason"].is_null());
}

TEST(FitLength, BadInputIsNamed)
{
    TemporaryFolder folder;
    std::map<std::string, std::string> nodes;
    formats::Project project =
        spanProject(folder.path(), kEnds, Vec3(0, 0, 0), Vec3(1, 0, 0), nodes);
    formats::HoseDefinition free = project.hoses[0];
    free.id = "loose";
    free.attachments.pop_back();
    project.hoses.push_back(free);
    const formats::ImportedScenes scenes =
        formats::importProjectScenes(project, folder / "p.ctproj", {});
    EXPECT_TRUE(betweenFixedEnds(project, project.hoses[0]));
    EXPECT_FALSE(betweenFixedEnds(project, project.hoses[1]));
    LengthFitOptions options;
    try {
        fitLengths(project, scenes, {"nope"}, options);
        ADD_FAILURE() << "an unknown hose was fitted";
    } catch (const InvalidArgument& error) {
        EXPECT_NE(std::string(error.what()).find("no hose 'nope'"), std::string::npos);
        EXPECT_NE(std::string(error.what()).find("probe, loose"), std::string::npos);
    }
    EXPECT_THROW(fitLengths(project, scenes, {"loose"}, options), InvalidArgument);
    const LengthFitReport all = fitLengths(project, scenes, {}, options);
    ASSERT_EQ(all.hoses.size(), 1u) << "only the hose between fixed ends";
    EXPECT_EQ(all.hoses[0].hoseId, "probe");
    options.tolerance = 0.0;
    EXPECT_THROW(fitLengths(project, scenes, {}, options), InvalidArgument);
}

TEST(FitLengthCli, TheMotionRigSampleExitCodesAndJson)
{
    const std::string sample = "\"" + (samplesDir() / "motion-rig.ctproj").string() + "\"";
    const CliRun text = runCli("check " + sample + " --fit-length -q");
    EXPECT_EQ(text.exitCode, 0) << text.output;
    EXPECT_NE(text.output.find("over 2 motion(s) (lever, carriage), 51 steps a sweep"),
              std::string::npos)
        << text.output;
    // Of its three hoses, carriage-cable (through two clips, its far end free) is not between
    // fixed ends: the other two are fitted.
    EXPECT_NE(text.output.find("2 hose(s) fitted, 0 without a valid length"), std::string::npos)
        << text.output;
    EXPECT_EQ(text.output.find("hose carriage-cable"), std::string::npos) << text.output;

    const CliRun json = runCli("check " + sample + " --fit-length --hose lever-feed --json -q");
    EXPECT_EQ(json.exitCode, 0) << json.output;
    const Json report = Json::parse(json.output);
    EXPECT_EQ(report["allValid"], true);
    EXPECT_EQ(report["motions"], Json::array({"lever", "carriage"}));
    EXPECT_EQ(report["sweptSteps"], 51);
    EXPECT_EQ(report["tolerance"], 0.001);
    ASSERT_EQ(report["hoses"].size(), 1u);
    const Json& lever = report["hoses"][0];
    EXPECT_EQ(lever["id"], "lever-feed");
    EXPECT_EQ(lever["valid"], true);
    EXPECT_LE(lever["shortest"].get<double>(), lever["length"].get<double>());
    EXPECT_LE(lever["length"].get<double>(), lever["longest"].get<double>());
    EXPECT_EQ(lever["currentValid"], true);
    EXPECT_EQ(lever["shortestLimit"], "taut");
    EXPECT_NEAR(lever["shortest"].get<double>(), lever["tautBound"].get<double>(), 0.001);
    EXPECT_TRUE(lever["reason"].is_null());
    EXPECT_GE(lever["sweeps"].get<int>(), 2);

    // The carriage's hose end sits 32 mm above the base plate: no length keeps 40 mm (exit 5).
    const CliRun none = runCli("check " + sample + " --fit-length --clearance 0.04 --json -q");
    EXPECT_EQ(none.exitCode, 5) << none.output;
    const Json failed = Json::parse(none.output);
    EXPECT_EQ(failed["allValid"], false);
    const Json& carriage = failed["hoses"].at(1);
    EXPECT_EQ(carriage["id"], "carriage-feed");
    EXPECT_EQ(carriage["valid"], false);
    EXPECT_TRUE(carriage["shortest"].is_null());
    EXPECT_EQ(carriage["invalidBy"], "clearance");
    EXPECT_EQ(carriage["limitingObject"], "rig:/motion-rig/base_plate");
    EXPECT_NEAR(carriage["limitingDistance"].get<double>(), 0.032, 1e-6);
    EXPECT_NE(carriage["reason"].get<std::string>().find("base_plate"), std::string::npos);
    const CliRun noneText = runCli("check " + sample + " --fit-length --clearance 0.04 -q");
    EXPECT_EQ(noneText.exitCode, 5);
    EXPECT_NE(noneText.output.find("hose carriage-feed (length 0.403 m): NO VALID LENGTH"),
              std::string::npos)
        << noneText.output;
}

TEST(FitLengthCli, NothingToFitBadHosesAndUsageErrorsHaveTheirExitCodes)
{
    // single-hose: no hose between fixed ends.
    const CliRun nothing =
        runCli("check \"" + (samplesDir() / "single-hose.ctproj").string() + "\" --fit-length");
    EXPECT_EQ(nothing.exitCode, 4) << nothing.output;
    EXPECT_NE(nothing.output.find("nothing to fit"), std::string::npos) << nothing.output;
    const std::string sample = "\"" + (samplesDir() / "motion-rig.ctproj").string() + "\"";
    const CliRun unknown = runCli("check " + sample + " --fit-length --hose nope -q");
    EXPECT_EQ(unknown.exitCode, 1);
    EXPECT_NE(unknown.output.find("no hose 'nope' in the project (hoses: lever-feed, "
                                  "carriage-feed, carriage-cable)"),
              std::string::npos)
        << unknown.output;
    const CliRun both = runCli("check " + sample + " --fit-length --sweep");
    EXPECT_EQ(both.exitCode, 2) << both.output;
    const CliRun hoseAlone = runCli("check " + sample + " --hose lever-feed --clearance 0.01");
    EXPECT_EQ(hoseAlone.exitCode, 2) << hoseAlone.output;
    const CliRun badTolerance = runCli("check " + sample + " --fit-length --tolerance -1");
    EXPECT_EQ(badTolerance.exitCode, 2) << badTolerance.output;
    const CliRun progress = runCli("check " + sample + " --fit-length --hose lever-feed");
    EXPECT_EQ(progress.exitCode, 0);
    EXPECT_NE(progress.output.find("  fit length 100 %"), std::string::npos) << progress.output;
    const CliRun help = runCli("check --help");
    EXPECT_EQ(help.exitCode, 0);
    EXPECT_NE(help.output.find("--fit-length"), std::string::npos);
    EXPECT_NE(help.output.find("5 --fit-length: a hose has no valid"), std::string::npos)
        << help.output;
}

} // namespace
} // namespace chaintube::exporting::testing
