// Motion sweeps (exporting::sweepMotions, `chaintube check --sweep`): the schedule rule, a hinge
// turning an attached end on a circle, a slider pulling a hose beyond its reach, an object
// sliding onto a hose, and the CLI's exit codes and JSON.
#include "cli_run.h"
#include "export_test_support.h"

#include <Eigen/Geometry>
#include <chaintube/export/sweep.h>
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

/// A project of one scene ("boxes.obj" in `folder`) and one straight 1 m hose from (0,0,0) to
/// (1,0,0), 20 segments, 5 % stretch, 0.1 m minimum bend radius; its ends fixed to the nodes
/// named `startNode` and `endNode` when given. `nodes` receives every node path by name.
formats::Project straightHoseProject(const fs::path& folder, const std::vector<Box>& boxes,
                                     const std::string& startNode, const std::string& endNode,
                                     std::map<std::string, std::string>& nodes)
{
    writeBoxes(folder / "boxes.obj", boxes);
    const formats::ImportedScene imported = formats::importScene(folder / "boxes.obj", {});
    for (const Box& b : boxes) {
        const std::vector<int> found = imported.findNodesByName(b.name);
        if (found.empty()) throw std::runtime_error(std::string("no node named ") + b.name);
        nodes[b.name] = imported.nodes[static_cast<size_t>(found.front())].path;
    }
    formats::Project project = formats::Project::withStandardPresets("sweep test");
    project.scenes.push_back({"boxes", "boxes.obj", {}});
    formats::HoseDefinition hose;
    hose.id = "probe";
    hose.route = {{0, 0, 0}, {1, 0, 0}};
    hose.length = 1.0;
    hose.material = Material{0.05, BendLimit::minBendRadius(0.1)};
    hose.outerDiameter = 0.02;
    hose.segmentCount = 20;
    if (!startNode.empty())
        hose.attachments.push_back({"boxes", nodes.at(startNode), Frame::identity(), 0, 0});
    if (!endNode.empty())
        hose.attachments.push_back({"boxes", nodes.at(endNode), Frame::identity(), 20, 20});
    project.hoses.push_back(hose);
    return project;
}

formats::PartMotion motion(const std::string& id, const std::string& node,
                           formats::PartMotion::Kind kind, const Vec3& axis, double minimum,
                           double maximum, const Vec3& point = Vec3::Zero())
{
    formats::PartMotion m;
    m.id = id;
    m.scene = "boxes";
    m.node = node;
    m.kind = kind;
    m.axis = axis;
    m.point = point;
    m.minimum = minimum;
    m.maximum = maximum;
    return m;
}

const std::vector<Box> kEnds{{"base", {-0.06, -0.03, -0.03}, {-0.02, 0.03, 0.03}},
                             {"lever", {0.96, -0.03, -0.03}, {1.04, 0.03, 0.03}}};

/// The straight hose with its end on "lever", which slides along +x from 0 to `maximum`.
fs::path writeSliderProject(const fs::path& folder, double maximum)
{
    std::map<std::string, std::string> nodes;
    formats::Project project = straightHoseProject(folder, kEnds, "base", "lever", nodes);
    project.motions = {motion("pull", nodes["lever"], formats::PartMotion::Kind::Slider,
                              Vec3::UnitX(), 0.0, maximum)};
    formats::saveProject(project, folder / "slider.ctproj");
    return folder / "slider.ctproj";
}

TEST(SweepSchedule, TIsDrivenOutAndBackAfterALeadInFromTheProjectPose)
{
    using Kind = formats::PartMotion::Kind;
    const std::vector<formats::PartMotion> motions{
        motion("h", "/a", Kind::Hinge, Vec3::UnitZ(), -0.5, 1.0),
        motion("s", "/b", Kind::Slider, Vec3::UnitX(), -0.05, 0.15)};
    // Lead-in: ceil(4 · max(0.5 / 1.5, 0.05 / 0.2)) = 2 steps.
    const std::vector<SweepStep> steps = sweepSchedule(motions, 4);
    ASSERT_EQ(steps.size(), 1u + 2u + 8u);
    EXPECT_EQ(steps[0].phase, SweepStep::Phase::ProjectPose);
    EXPECT_FALSE(steps[0].t);
    EXPECT_EQ(steps[0].values, (std::vector<double>{0.0, 0.0}));
    EXPECT_EQ(steps[1].phase, SweepStep::Phase::LeadIn);
    EXPECT_FALSE(steps[1].t);
    EXPECT_DOUBLE_EQ(steps[1].values[0], -0.25);
    EXPECT_DOUBLE_EQ(steps[1].values[1], -0.025);
    EXPECT_EQ(steps[2].t, 0.0);
    EXPECT_EQ(steps[2].values, (std::vector<double>{-0.5, -0.05}));
    for (int j = 1; j <= 4; ++j) {
        const SweepStep& out = steps[static_cast<size_t>(2 + j)];
        EXPECT_EQ(out.phase, SweepStep::Phase::Out);
        EXPECT_DOUBLE_EQ(*out.t, j / 4.0);
        EXPECT_DOUBLE_EQ(out.values[0], -0.5 + 1.5 * j / 4.0);
        EXPECT_DOUBLE_EQ(out.values[1], -0.05 + 0.2 * j / 4.0);
    }
    EXPECT_EQ(steps[6].values, (std::vector<double>{1.0, 0.15})) << "t = 1: exactly the maxima";
    for (int j = 3; j >= 0; --j) {
        const SweepStep& back = steps[static_cast<size_t>(10 - j)];
        EXPECT_EQ(back.phase, SweepStep::Phase::Back);
        EXPECT_DOUBLE_EQ(*back.t, j / 4.0);
    }
    EXPECT_EQ(steps.back().values, steps[2].values);
    // Every minimum at 0: no lead-in, the project's pose is t = 0.
    const std::vector<SweepStep> plain =
        sweepSchedule({motion("s", "/b", Kind::Slider, Vec3::UnitX(), 0.0, 0.1)}, 3);
    ASSERT_EQ(plain.size(), 7u);
    EXPECT_EQ(plain[0].t, 0.0);
    EXPECT_THROW(sweepSchedule(motions, 0), InvalidArgument);
    EXPECT_THROW(sweepSchedule({}, 4), InvalidArgument);
}

TEST(Sweep, AHingeTurnsTheAttachedEndOnACircleAndTheSpanFollows)
{
    // The end at P0 = (1, 0, 0) turns about z through C = (0.8, 0, 0): P(θ) = C + R(θ)(P0 − C),
    // the span from the fixed start (0, 0, 0) is sqrt(0.68 + 0.32 cos θ), 1 m … 0.8246 m.
    TemporaryFolder folder;
    std::map<std::string, std::string> nodes;
    formats::Project project = straightHoseProject(folder.path(), kEnds, "base", "lever", nodes);
    project.motions = {motion("flap", nodes["lever"], formats::PartMotion::Kind::Hinge,
                              Vec3(0.0, 0.0, 2.0), 0.0, std::numbers::pi / 2, Vec3(0.8, 0.0, 0.0))};
    const formats::ImportedScenes scenes =
        formats::importProjectScenes(project, folder / "p.ctproj", {});
    SweepOptions options;
    options.steps = 8;
    std::vector<Vec3> ends, starts;
    options.onStep = [&](int step, const std::vector<Hose>& hoses) {
        EXPECT_EQ(step, static_cast<int>(ends.size()));
        starts.push_back(hoses[0].point(0));
        ends.push_back(hoses[0].point(20));
    };
    const SweepReport report = sweepMotions(project, scenes, options);
    ASSERT_EQ(report.steps.size(), 17u);
    ASSERT_EQ(ends.size(), 17u);
    for (size_t s = 0; s < report.steps.size(); ++s) {
        const double angle = report.steps[s].values[0];
        EXPECT_NEAR(angle, std::numbers::pi / 2 * *report.steps[s].t, 1e-15);
        const Vec3 expected =
            Vec3(0.8, 0.0, 0.0) + Eigen::AngleAxisd(angle, Vec3::UnitZ()) * Vec3(0.2, 0.0, 0.0);
        EXPECT_NEAR((ends[s] - expected).norm(), 0.0, 1e-9) << "step " << s;
        EXPECT_NEAR((ends[s] - starts[s]).norm(), std::sqrt(0.68 + 0.32 * std::cos(angle)), 1e-9)
            << "step " << s;
        EXPECT_NEAR(starts[s].norm(), 0.0, 1e-12);
    }
    ASSERT_EQ(report.hoses.size(), 1u);
    const HoseSweep& hose = report.hoses[0];
    EXPECT_TRUE(hose.driven);
    EXPECT_FALSE(hose.violates());
    EXPECT_TRUE(hose.updates.empty()) << toString(hose.updates.front().status);
    EXPECT_LE(hose.worstStretch, 0.05 + 1e-9);
    EXPECT_GE(hose.smallestBendRadius, 0.1 * (1 - 1e-9));
    EXPECT_TRUE(hose.objects.empty()) << "both boxes are the hose's own attachment nodes";
    EXPECT_EQ(hose.stretchSeries.size(), 17u);
    EXPECT_EQ(hose.bendRadiusSeries.size(), 17u);
    EXPECT_EQ(hose.clearanceSeries.size(), 17u);
    EXPECT_FALSE(report.violations());
}

TEST(Sweep, ASliderPullingTheHoseBeyondItsReachIsReportedAtTheRightT)
{
    // The 1 m hose stretches to at most 1.05 m: the end, pulled 0.015 m a step (t = j / 12),
    // leaves its reach at the 4th step out (0.06 m) and is met again on the way back at 0.045 m
    // (t = 3 / 12, step 21).
    TemporaryFolder folder;
    const fs::path file = writeSliderProject(folder.path(), 0.18);
    SweepOptions options;
    options.steps = 12;
    const SweepReport report = sweepProject(file, {}, options);
    ASSERT_EQ(report.steps.size(), 25u);
    const HoseSweep& hose = report.hoses.at(0);
    EXPECT_TRUE(hose.beyondReach());
    EXPECT_TRUE(hose.violates());
    EXPECT_TRUE(report.violations());
    EXPECT_EQ(hose.firstUnmetStep, 4);
    EXPECT_DOUBLE_EQ(*report.steps[4].t, 4.0 / 12.0);
    EXPECT_DOUBLE_EQ(report.steps[4].values[0], 0.06);
    EXPECT_EQ(hose.unmetSteps, 17) << "out at 0.06 … 0.18 m, back at 0.165 … 0.06 m";
    EXPECT_EQ(hose.worstAttachmentGapStep, 12);
    EXPECT_NEAR(hose.worstAttachmentGap, 0.18 - 0.05, 1e-5);
    // Taut at the end of its band, less the 1e-6 of its reach the solver keeps (lib/README.md).
    EXPECT_NEAR(hose.worstStretch, 0.05, 2e-6);
    EXPECT_EQ(hose.overstretchedSteps, 0) << "lengths are never given up";
    ASSERT_FALSE(hose.updates.empty());
    EXPECT_EQ(hose.updates.front().step, 4);
    EXPECT_EQ(hose.updates.front().status, Status::Infeasible);
    EXPECT_NEAR(hose.updates.front().attachmentGap, 0.01, 1e-5);
    for (const SweepUpdate& update : hose.updates) {
        EXPECT_GE(update.step, 4);
        EXPECT_LE(update.step, 20);
    }
    EXPECT_NEAR(hose.stretchSeries[3], 0.045, 1e-6) << "within reach: stretched, met";
    EXPECT_NEAR(hose.stretchSeries[21], 0.045, 1e-6) << "met again on the way back";
}

TEST(Sweep, AnObjectSlidingOntoAFreeHoseIsACollisionAtTheRightSteps)
{
    // A plate 0.1 m above the hose's axis slides down 0.01 m a step (t = j / 10): the surface
    // distance is 0.09 − d, below 0.045 from d = 0.05 (step 5) and back up to step 15, and
    // −0.01 (the plate on the axis) at t = 1.
    TemporaryFolder folder;
    std::map<std::string, std::string> nodes;
    formats::Project project = straightHoseProject(
        folder.path(), {{"plate", {0.4, 0.1, -0.1}, {0.6, 0.12, 0.1}}}, "", "", nodes);
    project.motions = {motion("press", nodes["plate"], formats::PartMotion::Kind::Slider,
                              Vec3(0.0, -1.0, 0.0), 0.0, 0.1)};
    const formats::ImportedScenes scenes =
        formats::importProjectScenes(project, folder / "p.ctproj", {});
    SweepOptions options;
    options.steps = 10;
    options.clearanceThreshold = 0.045;
    options.reportDistance = 0.2;
    const SweepReport report = sweepMotions(project, scenes, options);
    const HoseSweep& hose = report.hoses.at(0);
    EXPECT_FALSE(hose.driven);
    ASSERT_EQ(hose.objects.size(), 1u);
    const ObjectSweep& plate = hose.objects[0];
    EXPECT_EQ(plate.objectPath, nodes["plate"]);
    EXPECT_TRUE(plate.collides());
    EXPECT_NEAR(plate.minDistance, -0.01, 1e-6);
    EXPECT_EQ(plate.step, 10);
    EXPECT_EQ(plate.firstStepBelowThreshold, 5);
    EXPECT_EQ(plate.lastStepBelowThreshold, 15);
    EXPECT_EQ(plate.stepsBelowThreshold, 11);
    for (int s = 0; s <= 10; ++s)
        EXPECT_NEAR(hose.clearanceSeries[static_cast<size_t>(s)], 0.09 - 0.01 * s, 1e-6) << s;
    EXPECT_TRUE(hose.collides());
    EXPECT_TRUE(report.violations());
    EXPECT_FALSE(hose.beyondReach());
    EXPECT_LT(hose.worstStretch, 1e-12) << "nothing moved the hose";
    // Only a collision with the default threshold 0: still a violation, at the same step.
    options.clearanceThreshold = 0.0;
    const SweepReport collisionsOnly = sweepMotions(project, scenes, options);
    EXPECT_EQ(collisionsOnly.hoses[0].objects.at(0).firstStepBelowThreshold, 10);
    EXPECT_EQ(collisionsOnly.hoses[0].objects.at(0).stepsBelowThreshold, 1);
    EXPECT_TRUE(collisionsOnly.violations());
}

TEST(Sweep, ProgressRisesToOneAndCancelStops)
{
    TemporaryFolder folder;
    const fs::path file = writeSliderProject(folder.path(), 0.04);
    SweepOptions options;
    options.steps = 5;
    std::vector<double> fractions;
    options.progress = [&](double fraction) {
        fractions.push_back(fraction);
        return true;
    };
    const SweepReport report = sweepProject(file, {}, options);
    EXPECT_FALSE(report.violations()) << "0.04 m stays within reach";
    ASSERT_FALSE(fractions.empty());
    EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
    EXPECT_DOUBLE_EQ(fractions.back(), 1.0);
    options.progress = [](double fraction) { return fraction < 0.5; };
    EXPECT_THROW(sweepProject(file, {}, options), formats::Cancelled);
    options.progress = {};
    options.steps = 0;
    EXPECT_THROW(sweepProject(file, {}, options), InvalidArgument);
}

TEST(SweepCli, ExitCodesAndTheJsonReport)
{
    TemporaryFolder folder;
    const fs::path file = writeSliderProject(folder.path(), 0.18);
    const std::string project = "\"" + file.string() + "\"";

    const CliRun text = runCli("check " + project + " --sweep --steps 12 -q");
    EXPECT_EQ(text.exitCode, 3) << text.output;
    EXPECT_NE(text.output.find("hose probe (on a moving part): VIOLATION"), std::string::npos)
        << text.output;
    EXPECT_NE(text.output.find("reach: an attachment beyond the hose's reach on 17 step(s), first "
                               "at step 4 (out, t 0.3333: pull 0.06 m)"),
              std::string::npos)
        << text.output;
    EXPECT_NE(text.output.find("infeasible at step 4"), std::string::npos) << text.output;
    EXPECT_EQ(text.output.find(" %\n"), std::string::npos) << "-q: no progress";

    const CliRun json = runCli("check " + project + " --sweep --steps 12 --json -q");
    EXPECT_EQ(json.exitCode, 3);
    const Json report = Json::parse(json.output);
    EXPECT_EQ(report["violations"], true);
    EXPECT_EQ(report["stepsEachWay"], 12);
    EXPECT_EQ(report["leadInSteps"], 0);
    EXPECT_EQ(report["clearanceThreshold"], 0.0);
    ASSERT_EQ(report["motions"].size(), 1u);
    EXPECT_EQ(report["motions"][0]["id"], "pull");
    EXPECT_EQ(report["motions"][0]["kind"], "slider");
    EXPECT_EQ(report["motions"][0]["unit"], "m");
    ASSERT_EQ(report["steps"].size(), 25u);
    EXPECT_EQ(report["steps"][0]["phase"], "project pose");
    EXPECT_EQ(report["steps"][4]["phase"], "out");
    EXPECT_DOUBLE_EQ(report["steps"][4]["t"].get<double>(), 4.0 / 12.0);
    EXPECT_DOUBLE_EQ(report["steps"][4]["values"][0].get<double>(), 0.06);
    EXPECT_EQ(report["steps"][13]["phase"], "back");
    const Json& hose = report["hoses"].at(0);
    EXPECT_EQ(hose["id"], "probe");
    EXPECT_EQ(hose["driven"], true);
    EXPECT_EQ(hose["violates"], true);
    EXPECT_EQ(hose["reach"]["firstUnmetStep"], 4);
    EXPECT_EQ(hose["reach"]["unmetSteps"], 17);
    EXPECT_NEAR(hose["reach"]["worstGap"].get<double>(), 0.13, 1e-5);
    EXPECT_NEAR(hose["stretch"]["worst"].get<double>(), 0.05, 2e-6);
    EXPECT_EQ(hose["stretch"]["band"], 0.05);
    EXPECT_EQ(hose["stretch"]["overstretchedSteps"], 0);
    EXPECT_TRUE(hose["stretch"]["firstOverstretchedStep"].is_null());
    EXPECT_EQ(hose["bend"]["minimumRadius"], 0.1);
    EXPECT_TRUE(hose["bend"]["smallestRadius"].is_null()) << "straight at every step";
    EXPECT_EQ(hose["updates"].at(0)["step"], 4);
    EXPECT_EQ(hose["updates"].at(0)["status"], "infeasible");
    EXPECT_EQ(hose["series"]["stretch"].size(), 25u);
    EXPECT_EQ(hose["series"]["clearance"].size(), 25u);
    EXPECT_TRUE(hose["objects"].is_array());

    // Within reach: exit 0.
    TemporaryFolder within;
    const CliRun ok = runCli("check \"" + writeSliderProject(within.path(), 0.04).string() +
                             "\" --sweep --steps 4 -q");
    EXPECT_EQ(ok.exitCode, 0) << ok.output;
    EXPECT_NE(ok.output.find("1 hose(s) swept over 9 steps, 0 with violations"), std::string::npos)
        << ok.output;
    // Progress on stderr unless -q.
    const CliRun progress =
        runCli("check \"" + (within.path() / "slider.ctproj").string() + "\" --sweep --steps 4");
    EXPECT_NE(progress.output.find("  sweep 100 %"), std::string::npos) << progress.output;
}

TEST(SweepCli, TheMotionRigSamplePassesAndBreaksAFourCentimetreClearance)
{
    // The lever turns from −0.5 to 0.8 rad and the carriage slides from −0.05 to 0.05 m: the
    // three hoses follow within their limits (the cable through the carriage's clip slides
    // through it); the carriage's hose end stays 32 mm above the base plate, so a 40 mm
    // clearance is broken at every step.
    const std::string sample = "\"" + (samplesDir() / "motion-rig.ctproj").string() + "\"";
    const CliRun passes = runCli("check " + sample + " --sweep -q");
    EXPECT_EQ(passes.exitCode, 0) << passes.output;
    EXPECT_NE(passes.output.find("hose lever-feed (on a moving part): ok"), std::string::npos)
        << passes.output;
    EXPECT_NE(passes.output.find("hose carriage-cable (on a moving part): ok"), std::string::npos)
        << passes.output;
    EXPECT_NE(passes.output.find("3 hose(s) swept over 51 steps, 0 with violations"),
              std::string::npos)
        << passes.output;
    const CliRun breaks = runCli("check " + sample + " --sweep --clearance 0.04 --json -q");
    EXPECT_EQ(breaks.exitCode, 3) << breaks.output;
    const Json report = Json::parse(breaks.output);
    ASSERT_EQ(report["hoses"].size(), 3u);
    // The clipped cable: driven by the carriage through its clip alone, every update Ok; the
    // base plate (its clamp's and guide's node) and the carriage (its clip's) are exempt from
    // clearance.
    const Json& cable = report["hoses"][2];
    EXPECT_EQ(cable["id"], "carriage-cable");
    EXPECT_EQ(cable["driven"], true);
    EXPECT_EQ(cable["violates"], false);
    EXPECT_TRUE(cable["updates"].empty());
    EXPECT_TRUE(cable["objects"].empty());
    EXPECT_EQ(report["hoses"][0]["id"], "lever-feed");
    EXPECT_EQ(report["hoses"][0]["violates"], false);
    EXPECT_TRUE(report["hoses"][0]["updates"].empty());
    const Json& carriage = report["hoses"][1];
    EXPECT_EQ(carriage["violates"], true);
    ASSERT_FALSE(carriage["objects"].empty());
    EXPECT_EQ(carriage["objects"][0]["path"], "/motion-rig/base_plate");
    EXPECT_NEAR(carriage["objects"][0]["minDistance"].get<double>(), 0.032, 1e-6);
    EXPECT_EQ(carriage["objects"][0]["collides"], false);
    EXPECT_EQ(carriage["objects"][0]["stepsBelowThreshold"], 51);
    EXPECT_EQ(report["leadInSteps"], 10);
}

// Without --clearance a sweep checks the project's own threshold ("checks"/"clearance") when
// it sets one: the motion rig with 40 mm breaks it as --clearance 0.04 does.
TEST(SweepCli, WithoutClearanceTheProjectsThresholdIsSwept)
{
    TemporaryFolder folder;
    fs::create_directories(folder / "scenes");
    fs::copy_file(samplesDir() / "scenes/motion-rig.gltf", folder / "scenes/motion-rig.gltf");
    formats::Project rig = formats::loadProject(samplesDir() / "motion-rig.ctproj");
    rig.checks.clearance = 0.04;
    const fs::path file = folder / "motion-rig.ctproj";
    formats::saveProject(rig, file);
    const CliRun own = runCli("check \"" + file.string() + "\" --sweep --json -q");
    EXPECT_EQ(own.exitCode, 3) << own.output;
    const Json report = Json::parse(own.output);
    EXPECT_EQ(report["hoses"][1]["objects"][0]["stepsBelowThreshold"], 51);
    const CliRun overridden = runCli("check \"" + file.string() + "\" --sweep -q --clearance 0");
    EXPECT_EQ(overridden.exitCode, 0) << overridden.output;
}

TEST(SweepCli, AProjectWithoutMotionsAndBadInputAreNamedWithTheirExitCodes)
{
    const fs::path single = samplesDir() / "single-hose.ctproj";
    const CliRun none = runCli("check \"" + single.string() + "\" --sweep");
    EXPECT_EQ(none.exitCode, 4) << none.output;
    EXPECT_NE(none.output.find("single-hose.ctproj: the project has no motions"), std::string::npos)
        << none.output;
    const CliRun absent = runCli("check /nonexistent/absent.ctproj --sweep");
    EXPECT_EQ(absent.exitCode, 1);
    EXPECT_NE(absent.output.find("/nonexistent/absent.ctproj"), std::string::npos);
    const CliRun zero = runCli("check x.ctproj --sweep --steps 0");
    EXPECT_EQ(zero.exitCode, 2);
    EXPECT_NE(zero.output.find("--steps"), std::string::npos) << zero.output;
    const CliRun jsonAlone = runCli("check x.ctproj --clearance 0.01 --json");
    EXPECT_EQ(jsonAlone.exitCode, 2);
    EXPECT_NE(jsonAlone.output.find("--json requires --sweep"), std::string::npos)
        << jsonAlone.output;
    const CliRun missing = runCli("check /nonexistent/x.ctproj");
    EXPECT_EQ(missing.exitCode, 1);
    EXPECT_NE(missing.output.find("/nonexistent/x.ctproj"), std::string::npos);
    const CliRun help = runCli("check --help");
    EXPECT_EQ(help.exitCode, 0);
    EXPECT_NE(help.output.find("--sweep --steps 40"), std::string::npos) << help.output;
}

} // namespace
} // namespace chaintube::exporting::testing
