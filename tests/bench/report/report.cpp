// chaintube-bench-report: speed against error for ChainTube and its peers, as Markdown, CSV
// and SVG. `--quick` (CI) finishes in well under a minute; the full run takes a few minutes.
//
//   ./build/tests/bench/chaintube-bench-report [--quick] [-o DIR]
#include "peers.h"
#include "svg_plot.h"

#include <chaintube/chaintube.h>
#include <chaintube/collision.h>

#ifdef CHAINTUBE_HAVE_EXPORT
#include <chaintube/export/gltf_export.h>
#include <chaintube/formats/project.h>
#include <chaintube/formats/project_hoses.h>
#include <chaintube/formats/scene_import.h>
#endif

#include "../realtime/machine.h"

#include <algorithm>
#include <chaintube/test_support/taut_span.h>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <map>
#include <numbers>
#include <sstream>

using namespace chaintube;
using namespace chaintube::bench;
using chaintube::test_support::TautSpan;

namespace {
constexpr double kHoseLength = 1.0;
/// The summary's second comparison counts only the XPBD runs that keep every segment within
/// this many percent of its rest length (a run that stretches it by more is not a hose).
constexpr double kHoseStretchPercent = 1.0;
constexpr const char* kHosePeer = "XPBD within 1 % (best)"; ///< its peer name in the tables
constexpr double kHoseRadius = 0.008;

// --- scenarios ------------------------------------------------------------------------------

struct Scenario
{
    std::string name;
    std::string description;
    std::string reference; ///< what the common reference is and why it is meaningful
    int fixStart = 0, fixEnd = 0;
    int frames = 60;
    std::function<RodSetup(int segments)> setup;
    std::function<FrameRequest(int frame, int frames, int segments)> request;
    /// Centreline error of a solver's final axis against the reference common to all solvers
    /// (metres): the largest distance of an axis point from the reference point at the same
    /// rest arclength.
    std::function<double(const std::vector<Vec3>& points, const RodSetup& setup)> error;
};

const double kBendRadius = 0.1; // minimum bend radius of the peer scenarios (m)
// Bullet's rope has no bend limit; its distance-2 bending links get this stiffness.
const double kBulletBendStiffness = 1.0;

// Rest arclength of every axis point.
std::vector<double> restArclength(const RodSetup& setup)
{
    std::vector<double> s(setup.axis.size(), 0.0);
    for (size_t i = 1; i < s.size(); ++i)
        s[i] = s[i - 1] + (setup.axis[i] - setup.axis[i - 1]).norm();
    return s;
}

// drag-middle reference: a free inextensible hose pulled by its middle point along +y far
// beyond its length trails behind the point as a hairpin: a half circle of the minimum bend
// radius R with the pulled point at its apex, then two straight legs parallel to the pull.
// `s` is the rest arclength from the apex, `side` ±1 the leg.
Vec3 hairpinPoint(const Vec3& apex, double s, double side)
{
    const Vec3 centre = apex - kBendRadius * Vec3::UnitY();
    if (s <= 0.5 * std::numbers::pi * kBendRadius) {
        const double phi = s / kBendRadius;
        return centre + kBendRadius * Vec3(side * std::sin(phi), std::cos(phi), 0.0);
    }
    return centre + Vec3(side * kBendRadius, -(s - 0.5 * std::numbers::pi * kBendRadius), 0.0);
}

const double kPullDistance = 4.0; // drag-middle: the final straight pull (m)

double hairpinError(const std::vector<Vec3>& points, const RodSetup& setup)
{
    const std::vector<double> s = restArclength(setup);
    const size_t middle = (points.size() - 1) / 2;
    const Vec3 apex(0.5, kPullDistance, 0.0);
    double best = 1e300;
    for (double side : {1.0, -1.0}) { // which leg is on which side is the path's choice
        double worst = 0.0;
        for (size_t i = 0; i < points.size(); ++i)
            worst = std::max(worst, (points[i] - hairpinPoint(apex, std::abs(s[i] - s[middle]),
                                                              i < middle ? side : -side))
                                        .norm());
        best = std::min(best, worst);
    }
    return best;
}

const double kBeyondReach = 0.01; // ends-fixed-middle-grab: final target above the apex (m)

// ends-fixed-middle-grab reference: the taut shape (test_support/taut_span.h).
const TautSpan& tautSpan()
{
    static const TautSpan taut = TautSpan::solve(0.8, 0.5, kBendRadius);
    return taut;
}

double tautSpanError(const std::vector<Vec3>& points, const RodSetup& setup)
{
    const std::vector<double> s = restArclength(setup);
    const double total = s.back();
    const TautSpan& taut = tautSpan();
    double worst = 0.0;
    for (size_t i = 0; i < points.size(); ++i)
        worst = std::max(worst, (points[i] - taut.along(s[i], total)).norm());
    return worst;
}

// moving-attachment: the clamp's frame at the end of the run (moved and turned, then pulled
// back along its own axis); reference: the straight hose carried rigidly by that frame.
const int kAttachmentTurnFrames = 40, kAttachmentPullFrames = 200;
const double kAttachmentPull = 4.0; // m, along the clamp's axis, away from the hose (2 cm a frame)

Frame attachmentFrame(int f)
{
    const double t = std::min(1.0, static_cast<double>(f + 1) / kAttachmentTurnFrames);
    Frame frame;
    frame.rotation = Quat(Eigen::AngleAxisd(1.2 * t, Vec3(0.0, 0.3, 1.0).normalized()));
    frame.translation = Vec3(0.4 * t, 0.3 * std::sin(std::numbers::pi * t), 0.0);
    if (f >= kAttachmentTurnFrames) {
        const double pull =
            kAttachmentPull * (f + 1 - kAttachmentTurnFrames) / kAttachmentPullFrames;
        frame.translation -= pull * (frame.rotation * Vec3::UnitX());
    }
    return frame;
}

double trailingError(const std::vector<Vec3>& points, const RodSetup& setup)
{
    const Frame final = attachmentFrame(kAttachmentTurnFrames + kAttachmentPullFrames - 1);
    double worst = 0.0;
    for (size_t i = 0; i < points.size(); ++i)
        worst = std::max(worst, (points[i] - final.apply(setup.axis[i])).norm());
    return worst;
}

// The catenary: span 1 m, hose length `length`, pins at the same height, gravity −y.
struct Catenary
{
    double length = 1.2, a = 0.0; // y = a cosh(x/a) + const
    static Catenary solve(double length)
    {
        Catenary c;
        c.length = length;
        double lo = 1e-3, hi = 1e3; // 2a sinh(1/2a) decreases in a towards 1
        for (int k = 0; k < 300; ++k) {
            const double mid = std::sqrt(lo * hi);
            (2 * mid * std::sinh(0.5 / mid) > length ? lo : hi) = mid;
        }
        c.a = std::sqrt(lo * hi);
        return c;
    }
    double sag() const { return a * (std::cosh(0.5 / a) - 1.0); }
    // Point at arclength s from the left pin (0, 0, 0); the right pin is (1, 0, 0).
    Vec3 point(double s) const
    {
        const double x = a * std::asinh((s - 0.5 * length) / a);
        return Vec3(0.5 + x, a * (std::cosh(x / a) - std::cosh(0.5 / a)), 0.0);
    }
};

std::vector<Vec3> straightAxis(int segments)
{
    std::vector<Vec3> axis;
    for (int i = 0; i <= segments; ++i)
        axis.emplace_back(kHoseLength * i / segments, 0.0, 0.0);
    return axis;
}

RodSetup radiusSetup(int segments, double radius, double expansion)
{
    RodSetup s;
    s.axis = straightAxis(segments);
    s.expansionCoefficient = expansion;
    s.minBendRadius = radius;
    return s;
}

Frame translation(const Vec3& t)
{
    Frame f;
    f.translation = t;
    return f;
}

const double kWrapRadius = 0.1;
const double kWrapStraight = 0.3; // length of each straight leg before the cylinder

// A hose laid around a cylinder of radius R (axis along z through (kWrapStraight, R)): in along
// y = 0, half way round, out along y = 2R. Closed form: lines and a semicircle of radius R.
std::vector<Vec3> wrapRoute()
{
    return {Vec3(0, 0, 0), Vec3(kWrapStraight + kWrapRadius, 0, 0),
            Vec3(kWrapStraight + kWrapRadius, 2 * kWrapRadius, 0), Vec3(0, 2 * kWrapRadius, 0)};
}

double wrapDistance(const Vec3& p)
{
    if (p.x() <= kWrapStraight)
        return std::min(std::hypot(p.y(), p.z()), std::hypot(p.y() - 2 * kWrapRadius, p.z()));
    return std::hypot(
        (Vec3(p.x(), p.y(), 0) - Vec3(kWrapStraight, kWrapRadius, 0)).norm() - kWrapRadius, p.z());
}

// Lays a hose along the wrap route at the given axis resolution; returns the time it took.
double layWrap(int segments, const BendLimit& limit, std::vector<Vec3>& axis, int repeats)
{
    HoseSpec spec;
    spec.segmentCount = segments;
    spec.material.expansionCoefficient = 0.0;
    spec.material.bendLimit = limit;
    double best = 1e300;
    for (int r = 0; r < repeats; ++r) {
        const auto start = std::chrono::steady_clock::now();
        const Hose hose = Hose::alongRoute(wrapRoute(), spec);
        best = std::min(
            best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        axis = hose.points();
    }
    return best;
}

double wrapError(const std::vector<Vec3>& axis)
{
    double worst = 0.0;
    for (size_t i = 0; i + 1 < axis.size(); ++i)
        worst =
            std::max({worst, wrapDistance(axis[i]), wrapDistance(0.5 * (axis[i] + axis[i + 1]))});
    return worst;
}

std::vector<Scenario> scenarios()
{
    // Every peer scenario uses an inextensible hose (expansion 0) with a minimum bend radius of
    // 0.1 m and ends in a state that does not depend on the path: a taut or trailing shape
    // whose closed form is known. The path before it is what a user would do (drag around,
    // move and turn the part); the error is measured at the final frame.
    std::vector<Scenario> list;
    list.push_back(
        {"drag-middle",
         "paper Fig. 6-9: free hose, middle point dragged round a loop in the xy plane (30 "
         "frames), then "
         "pulled 4 m along +y at 2 cm a frame (200 frames, 1.2 m/s at 60 Hz)",
         "the hairpin a long pull leaves: a half circle of radius R = 0.1 m with the pulled point "
         "at its "
         "apex and two straight legs trailing parallel to the pull. Whatever the loop did, a hose "
         "dragged "
         "by one point ends up trailing along the point's path; after 4 m (8 half-lengths of hose) "
         "only "
         "the hairpin that the bend limit forces remains. The plane is fixed (everything happens "
         "in z = 0); "
         "which leg lies on which side is left to the solver (the smaller error of the two counts)",
         0, 0, 230, [](int n) { return radiusSetup(n, kBendRadius, 0.0); },
         [](int f, int, int n) {
             FrameRequest r;
             if (f < 30) {
                 const double t = static_cast<double>(f + 1) / 30;
                 r.grabs.emplace_back(n / 2, Vec3(0.5 + 0.15 * std::sin(2 * std::numbers::pi * t),
                                                  0.25 * std::sin(std::numbers::pi * t), 0.0));
             } else {
                 r.grabs.emplace_back(n / 2, Vec3(0.5, kPullDistance * (f - 29) / 200.0, 0.0));
             }
             return r;
         },
         hairpinError});
    list.push_back({"moving-attachment",
                    "start segment fixed to an object that moves and turns (40 frames), then is "
                    "pulled 4 m back along "
                    "its own axis at 2 cm a frame (200 frames, 1.2 m/s at 60 Hz); free end",
                    "the taut straight span: the hose trails straight behind the clamp, i.e. the "
                    "rest shape carried "
                    "rigidly by the clamp's final frame",
                    2, 0, kAttachmentTurnFrames + kAttachmentPullFrames,
                    [](int n) { return radiusSetup(n, kBendRadius, 0.0); },
                    [](int f, int, int) {
                        FrameRequest r;
                        r.moveStart = true;
                        r.start = attachmentFrame(f);
                        return r;
                    },
                    trailingError});
    list.push_back(
        {"ends-fixed-middle-grab",
         "both ends pinned, brought 0.8 m apart (15 frames), middle grabbed along a 3-D path (30 "
         "frames), "
         "then pulled straight up to 1 cm beyond its reach and held (15 frames)",
         "the taut shape: from each pin a straight line tangent to a circle of radius R = 0.1 m, "
         "then the "
         "arc to the apex (closed form; the apex height solves one equation). Pulled beyond reach, "
         "an "
         "inextensible hose is taut and its shape unique; exactly at the apex it would not be (the "
         "discrete chain is slightly slack there, and a slack chain has many shapes). A solver "
         "that keeps "
         "its constraints stops at the apex; one that puts the point on the target overstretches "
         "by 1 cm "
         "at least",
         1, 1, 60, [](int n) { return radiusSetup(n, kBendRadius, 0.0); },
         [](int f, int, int n) {
             FrameRequest r;
             if (f < 15) { // bring the ends together first
                 r.moveEnd = true;
                 r.end = translation(Vec3(-0.2 * (f + 1) / 15, 0.0, 0.0));
             } else if (f < 45) {
                 const double t = static_cast<double>(f - 14) / 30;
                 r.grabs.emplace_back(n / 2, Vec3(0.4, 0.2 * std::sin(std::numbers::pi * t),
                                                  0.12 * std::sin(2 * std::numbers::pi * t)));
             } else {
                 const double t = std::min(1.0, static_cast<double>(f - 44) / 10);
                 r.grabs.emplace_back(n / 2,
                                      Vec3(0.4, t * (tautSpan().apexHeight + kBeyondReach), 0.0));
             }
             return r;
         },
         tautSpanError});
    return list;
}

// --- measuring ----------------------------------------------------------------------------

struct Run
{
    std::vector<Vec3> points;     ///< final axis of the repeat with the largest error
    double secondsPerFrame = 0.0; ///< best of the repeats
    double error = 0.0;           ///< centreline error, largest over the repeats
    double bestError = 0.0;       ///< centreline error, smallest over the repeats
};

using SolverFactory = std::function<std::unique_ptr<RodSolver>(const RodSetup&)>;

// Repeat r scales every grab target and every moved frame's translation by 1 + r·1e-15, a few
// units in the last place: a result that depends on rounding shows as a spread between the
// repeats (the two-pin clamp at fine resolutions does: which shape a nearly taut inextensible
// chain lands in; 1e-15 moved its 160-segment error between 11 and 83 mm). The error reported
// is the largest of the repeats, so a lucky rounding cannot make a run look accurate.
constexpr double kRoundingPerturbation = 1e-15;

FrameRequest perturbed(FrameRequest r, int repeat)
{
    const double scale = 1.0 + kRoundingPerturbation * repeat;
    for (auto& grab : r.grabs)
        grab.second *= scale;
    r.start.translation *= scale;
    r.end.translation *= scale;
    return r;
}

Run runScenario(const Scenario& scenario, const SolverFactory& factory, int segments, int repeats)
{
    Run run;
    double best = 1e300;
    run.bestError = 1e300;
    const RodSetup setup = scenario.setup(segments);
    for (int rep = 0; rep < repeats; ++rep) {
        std::unique_ptr<RodSolver> solver = factory(setup);
        if (scenario.fixStart) solver->fixStart(scenario.fixStart);
        if (scenario.fixEnd) solver->fixEnd(scenario.fixEnd);
        std::vector<FrameRequest> requests;
        for (int f = 0; f < scenario.frames; ++f)
            requests.push_back(perturbed(scenario.request(f, scenario.frames, segments), rep));
        const auto start = std::chrono::steady_clock::now();
        for (const FrameRequest& r : requests)
            solver->step(r);
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        best = std::min(best, seconds / scenario.frames);
        const std::vector<Vec3> points = solver->points();
        const double error = scenario.error(points, setup);
        run.bestError = std::min(run.bestError, error);
        if (rep == 0 || error > run.error) {
            run.error = error;
            run.points = points;
        }
    }
    run.secondsPerFrame = best;
    return run;
}

struct Violations
{
    double stretchPercent = 0.0; ///< largest |length/rest − 1| in %
    double bendExcess = 0.0;     ///< largest turn beyond the joint limit (rad)
    int selfIntersections = 0;   ///< segments whose rings cross (radius kHoseRadius)
};

Violations violations(const RodSetup& setup, const std::vector<Vec3>& p)
{
    Violations v;
    const size_t n = p.size();
    std::vector<double> halfTan(n, 0.0);
    for (size_t s = 0; s + 1 < n; ++s) {
        const double rest = (setup.axis[s + 1] - setup.axis[s]).norm();
        v.stretchPercent =
            std::max(v.stretchPercent, 100.0 * std::abs((p[s + 1] - p[s]).norm() / rest - 1.0));
    }
    for (size_t j = 1; j + 1 < n; ++j) {
        const Vec3 a = p[j] - p[j - 1], b = p[j + 1] - p[j];
        const double turn = std::atan2(a.cross(b).norm(), a.dot(b));
        const double rest = 0.5 * ((setup.axis[j] - setup.axis[j - 1]).norm() +
                                   (setup.axis[j + 1] - setup.axis[j]).norm());
        const double limit =
            setup.minBendRadius > 0
                ? jointDeflectionLimit(BendLimit::minBendRadius(setup.minBendRadius), rest)
                : setup.deflectionAngle;
        v.bendExcess = std::max(v.bendExcess, turn - limit);
        halfTan[j] = std::tan(0.5 * std::min(turn, 3.14));
    }
    for (size_t s = 0; s + 1 < n; ++s)
        if (kHoseRadius * (halfTan[s] + halfTan[s + 1]) > (p[s + 1] - p[s]).norm())
            ++v.selfIntersections;
    return v;
}

struct Row
{
    std::string scenario, solver;
    int segments = 0, sides = 0;
    double microseconds = 0;     ///< per update; ChainTube's includes its surface at `sides`
    double axisMicroseconds = 0; ///< per update, the solver alone (what equal-error compares)
    double centreline = 0, surface = 0; ///< largest over the repeats
    double bestCentreline = 0; ///< smallest over the repeats (rounding-level perturbations)
    Violations violation;
};

/// The fastest way a solver reaches each error: the Pareto front of its (error, time) runs.
struct Front
{
    struct Point
    {
        double error = 0, time = 0;
        std::string label;
        double stretchPercent = 0; ///< the run's largest |length/rest − 1|, %
    };
    std::vector<Point> points; ///< time ascending, error strictly descending

    static Front of(std::vector<Point> runs)
    {
        std::sort(runs.begin(), runs.end(), [](const Point& a, const Point& b) {
            return a.time < b.time || (a.time == b.time && a.error < b.error);
        });
        Front front;
        for (const Point& p : runs)
            if (std::isfinite(p.error) && std::isfinite(p.time) &&
                (front.points.empty() || p.error < front.points.back().error))
                front.points.push_back(p);
        return front;
    }
    /// Time to reach `error`: between two front runs, interpolated linearly in log(error) and
    /// log(time); at or above the fastest run's error, the fastest run's time (an upper bound:
    /// a coarser run than any measured might do); below the most accurate run: none.
    bool timeAt(double error, double& time, bool& upperBound) const
    {
        if (points.empty() || error < points.back().error) return false;
        upperBound = error >= points.front().error;
        if (upperBound) {
            time = points.front().time;
            return true;
        }
        for (size_t k = 1; k < points.size(); ++k)
            if (error >= points[k].error) {
                const Point &a = points[k - 1], &b = points[k];
                const double lo = std::log(std::max(b.error, 1e-300)),
                             hi = std::log(std::max(a.error, 1e-300));
                const double f =
                    hi > lo ? (std::log(std::max(error, 1e-300)) - lo) / (hi - lo) : 0.0;
                time = std::exp(std::log(b.time) + f * (std::log(a.time) - std::log(b.time)));
                return true;
            }
        time = points.back().time;
        return true;
    }
};

/// What an equal-error table found: the ratios (with whether each is only a lower bound) and
/// how many peer runs were more accurate than every ChainTube run.
struct EqualErrorSummary
{
    double minRatio = 1e300, maxRatio = 0.0;
    bool minIsLowerBound = false;
    int compared = 0, moreAccurate = 0;
    double bestPeerError = 1e300, bestChainTubeError = 1e300;
};

/// Markdown: for each run on the peer's front, ChainTube's interpolated time at the peer's
/// error and the ratio; where the peer is more accurate than every ChainTube run, says so.
std::string equalErrorTable(const Front& chaintube,
                            const std::vector<std::pair<std::string, Front>>& peers,
                            const std::string& unit, EqualErrorSummary* summary = nullptr)
{
    std::ostringstream md;
    md << "| peer | run | peer error (m) | peer " << unit << " | ChainTube " << unit
       << " at that error | ChainTube faster by |\n|---|---|---|---|---|---|\n";
    for (const auto& [name, front] : peers)
        for (const Front::Point& p : front.points) {
            double time = 0;
            bool upper = false;
            md << "| " << name << " | " << p.label << " | " << std::setprecision(3) << p.error
               << " | " << p.time << " | ";
            if (summary) {
                summary->bestPeerError = std::min(summary->bestPeerError, p.error);
                if (!chaintube.points.empty())
                    summary->bestChainTubeError = chaintube.points.back().error;
            }
            if (!chaintube.timeAt(p.error, time, upper)) {
                if (summary) ++summary->moreAccurate;
                if (chaintube.points.empty())
                    md << "— | no ChainTube run with a finite error |\n";
                else
                    md << "— | peer more accurate than every ChainTube run (best "
                       << chaintube.points.back().error << " m) |\n";
                continue;
            }
            const double ratio = p.time / time;
            if (summary) {
                ++summary->compared;
                if (ratio < summary->minRatio)
                    summary->minRatio = ratio, summary->minIsLowerBound = upper;
                summary->maxRatio = std::max(summary->maxRatio, ratio);
            }
            md << (upper ? "≤ " : "") << time << (upper ? " (coarsest run)" : "") << " | "
               << (upper ? "≥ " : "") << ratio << "x" << (ratio < 1 ? " (peer faster)" : "")
               << " |\n";
        }
    return md.str();
}

double ringError(int sides)
{
    return kHoseRadius * (1 - std::cos(std::numbers::pi / sides));
}

// Surface update cost of one hose (rings, normals) at this resolution, µs.
double surfaceMicroseconds(int segments, int sides, int repeats)
{
    HoseSpec spec;
    spec.segmentCount = segments;
    spec.profile = Profile::circle(kHoseRadius, sides);
    Hose hose = Hose::straight(Vec3::Zero(), Vec3::UnitX(), kHoseLength, spec);
    static_cast<void>(hose.grab(segments / 2, Vec3(0.5, 0.2, 0.1)));
    HoseSurface surface(hose);
    const int loops = std::max(50, 20000 / segments) * repeats;
    const auto start = std::chrono::steady_clock::now();
    for (int k = 0; k < loops; ++k) {
        surface.invalidate();
        surface.update(hose);
    }
    return 1e6 * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() /
           loops;
}

std::string fmt(double value, int precision = 3)
{
    std::ostringstream out;
    out << std::setprecision(precision) << value;
    return out.str();
}

/// A summary's "ChainTube faster by" cell: the range of its ratios ("≥": a lower bound), or "—".
std::string ratioRange(const EqualErrorSummary& sum)
{
    if (!sum.compared) return "—";
    return (sum.minIsLowerBound ? "≥ " : "") + fmt(sum.minRatio) + "x … " + fmt(sum.maxRatio) + "x";
}

// The paper's target frame: 50 hoses × 100 points × 16-sided rings, `moving` of them dragged
// each frame (axis, rings, normals). Best mean over `rounds` runs of `frames` frames, µs.
double frameMicroseconds(int moving, int frames, int rounds, size_t& vertexBytes)
{
    Scene scene;
    for (int i = 0; i < 50; ++i) {
        HoseSpec spec;
        spec.outerDiameter = 2 * kHoseRadius;
        spec.segmentCount = 99;
        spec.material.expansionCoefficient = 0.1;
        spec.material.bendLimit = BendLimit::minBendRadius(0.08);
        spec.profile = Profile::circle(kHoseRadius, 16);
        scene.addHose(Hose::straight(Vec3(0.0, 0.0, 0.05 * i), Vec3::UnitX(), 1.0, spec));
    }
    vertexBytes = 0;
    for (int i = 0; i < 50; ++i)
        vertexBytes +=
            4 * (scene.surface(i).positions().size() + scene.surface(i).normals().size());
    double best = 1e300;
    int frame = 0;
    for (int round = 0; round < rounds; ++round) {
        const auto start = std::chrono::steady_clock::now();
        for (int f = 0; f < frames; ++f, ++frame) {
            for (int i = 0; i < moving; ++i) {
                const double phase = 0.05 * frame + 0.3 * i;
                static_cast<void>(scene.hose(i).grab(
                    50, Vec3(0.5 + 0.2 * std::sin(phase), 0.2 * std::cos(phase), 0.05 * i)));
            }
            scene.updateSurfaces();
        }
        best = std::min(
            best,
            1e6 * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() /
                frames);
    }
    return best;
}

double memsetMicroseconds(size_t bytes, int rounds)
{
    std::vector<char> buffer(bytes);
    double best = 1e300;
    for (int round = 0; round < rounds; ++round) {
        const auto start = std::chrono::steady_clock::now();
        for (int k = 0; k < 200; ++k) {
            std::memset(buffer.data(), k & 0xff, buffer.size());
            asm volatile("" : : "r"(buffer.data()) : "memory");
        }
        best = std::min(
            best,
            1e6 * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() /
                200);
    }
    return best;
}

// Cost of the features beyond the paper, each against the same update without it:
// a 100-point hose laid in a U, its start clamped, its middle point moved on a 2 cm circle each
// frame (grab + surface). `configure` switches the feature on; `frame` may add work of the
// feature's own (e.g. turning a clamp). Returns µs per frame (best of rounds) and the final
// surface positions, so the caller can tell whether the feature changed anything at all.
struct FeatureRun
{
    double microseconds = 0.0;
    std::vector<float> positions;
    std::vector<Vec3> axis;
};

FeatureRun featureFrame(const std::function<void(HoseSpec&)>& configure,
                        const std::function<void(Hose&)>& prepare, bool rollClamp, int frames,
                        int rounds)
{
    FeatureRun result;
    double best = 1e300;
    for (int round = 0; round < rounds; ++round) {
        HoseSpec spec;
        spec.segmentCount = 99;
        spec.material.expansionCoefficient = 0.05;
        spec.material.bendLimit = BendLimit::minBendRadius(0.1);
        spec.profile = Profile::circle(kHoseRadius, 16);
        configure(spec);
        Hose hose = Hose::alongRoute({Vec3(0, 0, 0), Vec3(0.2, 0, 0), Vec3(0.3, -0.25, 0),
                                      Vec3(0.5, -0.25, 0), Vec3(0.6, 0, 0), Vec3(0.8, 0, 0)},
                                     spec);
        const int clamp = hose.attach(0, 1, Frame::identity());
        if (prepare) prepare(hose);
        HoseSurface surface(hose);
        const int middle = hose.pointCount() / 2;
        const Vec3 laid = hose.points()[static_cast<size_t>(middle)];
        const auto start = std::chrono::steady_clock::now();
        for (int f = 0; f < frames; ++f) {
            const double phase = 2 * std::numbers::pi * (f + 1) / frames;
            if (rollClamp) { // turn the clamp about the hose's axis there (+x), a quarter turn
                Frame frame;
                frame.rotation = Quat(
                    Eigen::AngleAxisd(0.5 * std::numbers::pi * (f + 1) / frames, Vec3::UnitX()));
                static_cast<void>(hose.moveAttachment(clamp, frame));
            }
            static_cast<void>(
                hose.grab(middle, laid + 0.02 * Vec3(std::cos(phase) - 1, std::sin(phase), 0)));
            static_cast<void>(hose.step()); // per-frame gravity; one comparison when it is off
            surface.update(hose);
        }
        best = std::min(
            best,
            1e6 * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() /
                frames);
        result.positions.assign(surface.positions().begin(), surface.positions().end());
        result.axis = hose.points();
    }
    result.microseconds = best;
    return result;
}

void writeFile(const std::filesystem::path& path, const std::string& text)
{
    std::ofstream out(path);
    out << text;
    if (!out) throw std::runtime_error("cannot write " + path.string());
}
} // namespace

int main(int argc, char** argv)
{
    bool quick = false;
    std::string only, onlyPeer; // --scenario, --peer: one scenario / solver (while working on it)
    std::filesystem::path outDir = "bench-report";
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--quick"))
            quick = true;
        else if (!std::strcmp(argv[i], "-o") && i + 1 < argc)
            outDir = argv[++i];
        else if (!std::strcmp(argv[i], "--scenario") && i + 1 < argc)
            only = argv[++i];
        else if (!std::strcmp(argv[i], "--peer") && i + 1 < argc)
            onlyPeer = argv[++i];
        else {
            std::cerr
                << "usage: chaintube-bench-report [--quick] [-o DIR] [--scenario NAME] [--peer "
                   "NAME]\n"
                   "Writes report.md, report.csv, speed-vs-error-<scenario>.svg and "
                   "convergence.svg to DIR\n"
                   "(default ./bench-report). --quick: fewer resolutions and repeats (CI).\n"
                   "--scenario, --peer: measure only that scenario / solver (a partial report).\n";
            return std::strcmp(argv[i], "--help") == 0 ? 0 : 2;
        }
    }
    std::filesystem::create_directories(outDir);
    auto loadAverage = [] {
        std::ifstream in("/proc/loadavg");
        std::string oneMinute;
        return (in >> oneMinute) ? oneMinute : std::string("unknown");
    };
    const std::string loadAtStart = loadAverage();
    std::string command = "chaintube-bench-report";
    for (int i = 1; i < argc; ++i)
        command += std::string(" ") + argv[i];
    const std::string provenance = "Commit " + realtime::gitCommit(CHAINTUBE_SOURCE_DIR) + ", " +
                                   realtime::utcDate() + ", " + realtime::cpuModel() +
                                   ", CPUs allowed: " + realtime::allowedCpus() + ". Command: `" +
                                   command + "`.\n\n";
    const std::vector<int> resolutions =
        quick ? std::vector<int>{10, 20, 40} : std::vector<int>{10, 20, 40, 80, 160};
    const std::vector<int> ringSides =
        quick ? std::vector<int>{8, 16} : std::vector<int>{8, 16, 32};
    const int repeats = quick ? 1 : 5; // best of: the machine is shared

    struct Peer
    {
        std::string name;
        SolverFactory factory;
    };
    std::vector<Peer> peers = {
        {"ChainTube", [](const RodSetup& s) { return makeChainTubeRod(s); }}};
    for (int it : {1, 4, 16, 64})
        peers.push_back({"XPBD x" + std::to_string(it),
                         [it](const RodSetup& s) { return makeXpbdRod(s, it); }});
#ifdef CHAINTUBE_HAVE_BULLET
    for (int it : {4, 16, 64})
        peers.push_back({"Bullet rope x" + std::to_string(it), [it](const RodSetup& s) {
                             return makeBulletRope(s, it, kBulletBendStiffness);
                         }});
#endif

    std::vector<Row> rows;
    std::map<std::string, double> surfaceCost;                      // "segments/sides" → µs
    surfaceMicroseconds(resolutions.front(), ringSides.front(), 1); // warm up (first-touch, clocks)
    for (int n : resolutions)
        for (int sides : ringSides)
            surfaceCost[std::to_string(n) + "/" + std::to_string(sides)] =
                surfaceMicroseconds(n, sides, repeats);

    std::map<std::string, std::vector<PlotSeries>> scenarioPlots;
    const char* colours[] = {"#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#8c564b",
                             "#ff7f0e", "#17becf", "#7f7f7f", "#bcbd22"};
    // Per scenario: every solver's (error, axis time) runs, for the equal-error tables.
    std::map<std::string, std::map<std::string, std::vector<Front::Point>>> runsOf;
    for (const Scenario& scenario : scenarios()) {
        if (!only.empty() && scenario.name != only) continue;
        std::cerr << "scenario " << scenario.name << "\n";
        for (const Peer& peer : peers) {
            if (!onlyPeer.empty() && peer.name != onlyPeer) continue;
            for (int n : resolutions) {
                const Run run = runScenario(scenario, peer.factory, n, repeats);
                const RodSetup setup = scenario.setup(n);
                const double error = run.error;
                const Violations v = violations(setup, run.points);
                runsOf[scenario.name][peer.name].push_back({error, 1e6 * run.secondsPerFrame,
                                                            std::to_string(n) + " segments",
                                                            v.stretchPercent});
                for (int sides : ringSides) {
                    Row row{scenario.name,
                            peer.name,
                            n,
                            sides,
                            1e6 * run.secondsPerFrame,
                            1e6 * run.secondsPerFrame,
                            error,
                            error + ringError(sides),
                            run.bestError,
                            v};
                    if (peer.name == "ChainTube")
                        row.microseconds +=
                            surfaceCost[std::to_string(n) + "/" + std::to_string(sides)];
                    rows.push_back(row);
                }
            }
        }
    }

    if (!only.empty() || !onlyPeer.empty()) {
        // A partial run: the rows only (the report's cross-scenario sections need them all).
        if (rows.empty()) {
            std::cerr << "chaintube-bench-report: no scenario/solver matches --scenario '" << only
                      << "' --peer '" << onlyPeer << "'; scenarios:";
            for (const Scenario& scenario : scenarios())
                std::cerr << " " << scenario.name;
            std::cerr << "; solvers:";
            for (const Peer& peer : peers)
                std::cerr << " '" << peer.name << "'";
            std::cerr << "\n";
            return 2;
        }
        std::cout << "| scenario | solver | segments | sides | axis µs/update | centreline error | "
                     "stretch % | bend excess |\n";
        for (const Row& row : rows)
            if (row.sides == ringSides.front())
                std::cout << "| " << row.scenario << " | " << row.solver << " | " << row.segments
                          << " | " << row.sides << " | " << fmt(row.axisMicroseconds) << " | "
                          << fmt(row.centreline) << " | " << fmt(row.violation.stretchPercent)
                          << " | " << fmt(row.violation.bendExcess) << " |\n";
        return 0;
    }

    // Wrap (closed form): lay the hose round a cylinder; and convergence of the datasheet
    // radius against the paper's fixed angle (chosen to give R at the coarsest resolution).
    std::vector<std::pair<double, double>> radiusConvergence, angleConvergence;
    std::ostringstream wrapTable;
    const std::vector<int> convergenceResolutions =
        quick ? std::vector<int>{15, 30, 60, 120} : std::vector<int>{15, 30, 60, 120, 240, 480};
    const double wrapLength = 2 * kWrapStraight + std::numbers::pi * kWrapRadius;
    const double fixedAngle = jointDeflectionLimit(BendLimit::minBendRadius(kWrapRadius),
                                                   wrapLength / convergenceResolutions.front());
    wrapTable << "| segments | lay-out time µs | error, min bend radius " << kWrapRadius
              << " m | error, fixed " << fmt(fixedAngle * 180 / std::numbers::pi)
              << "° per joint (paper) |\n|---|---|---|---|\n";
    for (int n : convergenceResolutions) {
        std::vector<Vec3> axis;
        const double seconds = layWrap(n, BendLimit::minBendRadius(kWrapRadius), axis, repeats);
        radiusConvergence.emplace_back(n, wrapError(axis));
        layWrap(n, BendLimit::deflectionAngle(fixedAngle), axis, 1);
        angleConvergence.emplace_back(n, wrapError(axis));
        wrapTable << "| " << n << " | " << fmt(1e6 * seconds) << " | "
                  << fmt(radiusConvergence.back().second) << " | "
                  << fmt(angleConvergence.back().second) << " |\n";
    }

    // Model only what a scene needs: tolerance → resolution → time.
    std::ostringstream tolerances;
    tolerances
        << "| tolerance | segment length | segments per metre | ring sides | centreline bound | "
           "ring bound | update µs (1 m hose, drag + surface) |\n|---|---|---|---|---|---|---|\n";
    for (double tolerance : {1e-2, 3e-3, 1e-3, 3e-4, 1e-4}) {
        const Resolution r = resolutionFor(tolerance, BendLimit::minBendRadius(0.1), kHoseRadius);
        const int segments =
            std::max(1, static_cast<int>(std::ceil(kHoseLength / r.segmentLength)));
        const Scenario drag = scenarios().front();
        const Run run = runScenario(
            drag, [](const RodSetup& s) { return makeChainTubeRod(s); }, segments, repeats);
        tolerances << "| " << fmt(tolerance * 1e3) << " mm | " << fmt(r.segmentLength * 1e3)
                   << " mm | " << segments << " | " << r.ringSides << " | "
                   << fmt(r.centrelineError * 1e3) << " mm | " << fmt(r.ringError * 1e3) << " mm | "
                   << fmt(1e6 * run.secondsPerFrame + surfaceMicroseconds(segments, r.ringSides, 1))
                   << " |\n";
    }

    // Catenary (closed form): a hose hung between points 1 m apart, inextensible, no bend limit.
    std::ostringstream catenaryTable;
    catenaryTable << "| length | segments | sag | catenary | error | settle time s | rounds "
                     "|\n|---|---|---|---|---|---|---|\n";
    for (const auto& [length, expected] :
         {std::pair{1.05, 0.13930}, std::pair{1.2, 0.29234}, std::pair{2.0, 0.79639}}) {
        const int segments = 64;
        HoseSpec spec;
        spec.segmentCount = segments;
        spec.material.expansionCoefficient = 0.0;
        spec.material.bendLimit = BendLimit::minBendRadius(0.0);
        const double half = 0.5 * length, depth = std::sqrt(half * half - 0.25);
        Hose hose = Hose::alongRoute({Vec3(0, 0, 0), Vec3(0.5, -depth, 0.0), Vec3(1, 0, 0)}, spec);
        hose.attach(0, 0, Frame::identity());
        hose.attach(segments, segments, Frame::identity());
        const auto start = std::chrono::steady_clock::now();
        const SagResult result = hose.sag();
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        double lowest = 0.0;
        for (const Vec3& p : hose.points())
            lowest = std::min(lowest, p.y());
        catenaryTable << "| " << length << " m | " << segments << " | " << fmt(-lowest, 5) << " | "
                      << expected << " | " << fmt(100.0 * (-lowest - expected) / expected, 2)
                      << " % | " << fmt(seconds) << " | " << result.rounds << " |\n";
    }

    // The catenary against the peers: every solver settles the same hose (1.2 m hung between
    // pins 1 m apart, inextensible, no bend limit) from the same V under gravity; the error
    // against the catenary after 1, 2, 4, … frames, and the solver time it took to get there.
    const Catenary catenary = Catenary::solve(1.2);
    std::ostringstream catenaryPeers;
    std::vector<Front::Point> catenaryChainTube;
    std::vector<std::pair<std::string, Front>> catenaryFronts;
    std::vector<Front::Point> catenaryXpbdHose; // XPBD states within kHoseStretchPercent
    double catenaryStartError = 0.0;
    std::ostringstream catenaryCsv; // microseconds = time to settle to that state
    {
        const std::vector<int> catenaryResolutions =
            quick ? std::vector<int>{16, 32} : std::vector<int>{16, 32, 64, 128};
        const int maxFrames = quick ? 128 : 2048;
        constexpr int kEveryFrameUpTo =
            64; // checkpoints: every frame up to here, then powers of two
        std::vector<Peer> gravityPeers = {
            {"ChainTube", [](const RodSetup& s) { return makeChainTubeRod(s); }}};
        for (int it : {4, 16, 64})
            gravityPeers.push_back({"XPBD x" + std::to_string(it),
                                    [it](const RodSetup& s) { return makeXpbdRod(s, it); }});
#ifdef CHAINTUBE_HAVE_BULLET
        for (int it : {4, 16, 64})
            gravityPeers.push_back({"Bullet rope x" + std::to_string(it),
                                    [it](const RodSetup& s) { return makeBulletRope(s, it); }});
#endif
        catenaryPeers << "| solver | segments | error after 8 frames (m) | after 64 | after "
                      << maxFrames
                      << " | solver µs per frame | max stretch % at the end "
                         "|\n|---|---|---|---|---|---|---|\n";
        std::vector<PlotSeries>& plot = scenarioPlots["catenary"];
        size_t colour = 0;
        for (const Peer& peer : gravityPeers) {
            std::vector<Front::Point> points;
            for (int n : catenaryResolutions) {
                RodSetup setup;
                const double depth = std::sqrt(0.25 * catenary.length * catenary.length - 0.25);
                for (int i = 0; i <= n; ++i) { // a V of straight legs, uniform rest arclength
                    const double u = 2.0 * i / n;
                    setup.axis.push_back(u <= 1.0 ? Vec3(0.5 * u, -depth * u, 0.0)
                                                  : Vec3(0.5 * u, -depth * (2.0 - u), 0.0));
                }
                setup.noBendLimit = true;
                setup.gravity = Vec3(0.0, -9.81, 0.0);
                const std::vector<double> arclength = restArclength(setup);
                auto error = [&](const std::vector<Vec3>& p) {
                    double worst = 0.0;
                    for (size_t i = 0; i < p.size(); ++i)
                        worst = std::max(worst, (p[i] - catenary.point(arclength[i])).norm());
                    return worst;
                };
                const double startError = error(setup.axis);
                catenaryStartError = startError;
                std::map<int, double> errorAt, stretchAt,
                    secondsAt; // per checkpoint: the best time of the repeats
                std::unique_ptr<RodSolver> solver;
                for (int rep = 0; rep < repeats; ++rep) {
                    solver = peer.factory(setup);
                    solver->fixStart(1);
                    solver->fixEnd(1);
                    double seconds = 0.0;
                    for (int f = 1; f <= maxFrames; ++f) {
                        const auto start = std::chrono::steady_clock::now();
                        solver->step(FrameRequest());
                        seconds +=
                            std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
                                .count();
                        if (f <= kEveryFrameUpTo || (f & (f - 1)) == 0) {
                            errorAt[f] = error(solver->points());
                            stretchAt[f] = violations(setup, solver->points()).stretchPercent;
                            secondsAt[f] = rep == 0 ? seconds : std::min(secondsAt[f], seconds);
                        }
                    }
                }
                const double seconds = secondsAt[maxFrames];
                // Only states that removed 90 % of the starting V's error count as settled
                // enough to compare (a solver that has barely moved is "fast" but not settling).
                for (const auto& [f, e] : errorAt)
                    catenaryCsv << "catenary," << peer.name << "," << n << ",,"
                                << 1e6 * secondsAt[f] << "," << e << ",,,,," << f << "\n";
                for (const auto& [f, e] : errorAt)
                    if (e < 0.1 * startError)
                        points.push_back(
                            {e, 1e6 * secondsAt[f],
                             std::to_string(n) + " segments, " + std::to_string(f) + " frames",
                             stretchAt[f]});
                catenaryPeers << "| " << peer.name << " | " << n << " | " << fmt(errorAt[8])
                              << " | " << fmt(errorAt[64]) << " | " << fmt(errorAt[maxFrames])
                              << " | " << fmt(1e6 * seconds / maxFrames) << " | "
                              << fmt(violations(setup, solver->points()).stretchPercent) << " |\n";
            }
            PlotSeries series{peer.name, colours[colour++ % 9], {}, true};
            for (const Front::Point& p : Front::of(points).points)
                series.points.emplace_back(p.error, p.time);
            plot.push_back(series);
            if (peer.name == "ChainTube")
                catenaryChainTube = points;
            else
                catenaryFronts.emplace_back(peer.name, Front::of(points));
            if (peer.name.rfind("XPBD", 0) == 0)
                for (const Front::Point& p : points)
                    if (p.stretchPercent <= kHoseStretchPercent)
                        catenaryXpbdHose.push_back(
                            {p.error, p.time, peer.name + ", " + p.label, p.stretchPercent});
        }
    }

    // The 50-hose frame and its physical bound.
    std::ostringstream frameTable;
    {
        size_t bytes = 0;
        const int frames = quick ? 50 : 400, rounds = quick ? 2 : 5;
        const double all = frameMicroseconds(50, frames, rounds, bytes);
        const double five = frameMicroseconds(5, frames, rounds, bytes);
        const double one = frameMicroseconds(1, frames, rounds, bytes);
        const double bound = memsetMicroseconds(bytes, rounds);
        frameTable << "| hoses moving (of 50) | µs per frame | × memset of the frame's "
                   << fmt(bytes / 1e6) << " MB |\n|---|---|---|\n"
                   << "| 50 | " << fmt(all) << " | " << fmt(all / bound) << " |\n"
                   << "| 5 | " << fmt(five) << " | " << fmt(five / bound) << " |\n"
                   << "| 1 | " << fmt(one) << " | " << fmt(one / bound) << " |\n"
                   << "| (memset) | " << fmt(bound) << " | 1 |\n";
    }

    // Import of the engine scene and export of the 50-hose engine sample (needs ../shared).
    std::ostringstream pipelineTable, engineTable;
    std::vector<double> engineErrors; // every engine figure, checked to be finite
#ifdef CHAINTUBE_HAVE_EXPORT
    {
        const std::filesystem::path scenes = CHAINTUBE_SCENES_DIR;
        const std::filesystem::path engine = scenes / "2CylinderEngine.glb";
        const std::filesystem::path project =
            std::filesystem::path(CHAINTUBE_SAMPLES_DIR) / "engine-50-hoses.ctproj";
        if (std::filesystem::exists(engine)) {
            std::filesystem::create_directories(outDir / ".export-timing"); // removed after timing
            double importBest = 1e300, exportBest = 1e300;
            for (int round = 0; round < (quick ? 1 : 3); ++round) {
                auto start = std::chrono::steady_clock::now();
                const formats::ImportedScene scene = formats::importScene(engine);
                importBest =
                    std::min(importBest,
                             std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
                                 .count());
                start = std::chrono::steady_clock::now();
                exporting::exportProjectFile(project,
                                             outDir / ".export-timing" / "engine-50-hoses.glb",
                                             {{"scenes", scenes}});
                exportBest =
                    std::min(exportBest,
                             std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
                                 .count());
                (void)scene;
            }
            std::filesystem::remove_all(outDir / ".export-timing");
            pipelineTable
                << "| step | seconds | target |\n|---|---|---|\n| import 2CylinderEngine.glb | "
                << fmt(importBest)
                << " | < 1 |\n| export samples/engine-50-hoses.ctproj (import + build + GLB) | "
                << fmt(exportBest) << " | < 1 |\n";
            // The 50-hose engine sample, error and time per resolution. The frame: every hose's
            // middle point moved on a 2 cm circle round where it was laid (the hoses are fixed to
            // the engine's parts, so most of these are grabs between two fixed runs), then every
            // surface updated. Error: the lay-out along the authored routes (rounded corners of
            // the material's bend radius) against the same route laid out at 16x the resolution,
            // whose own error is 1/256 of it (the sagitta l^2/8R, see the wrap section): the
            // largest distance of an axis point or segment midpoint from the fine polyline.
            const formats::Project engineProject = formats::loadProject(project);
            const formats::ImportedScenes imported =
                formats::importProjectScenes(engineProject, project, {{"scenes", scenes}});
            auto hosesAt = [&](int scale, int sides) {
                formats::Project scaled = engineProject;
                for (formats::HoseDefinition& hose : scaled.hoses) {
                    if (hose.segmentCount > 0)
                        hose.segmentCount *= scale;
                    else
                        hose.segmentLength /= scale;
                    hose.profile.sides = sides;
                    for (formats::HoseAttachment& a : hose.attachments) // the same run of hose
                        a.firstPoint *= scale, a.lastPoint *= scale;
                }
                return formats::buildHoses(scaled, imported);
            };
            engineTable << "| axis resolution | axis points (50 hoses) | ring sides | µs per frame "
                           "(50 moving) | "
                           "centreline error of the lay-out (max over hoses) | surface error bound "
                           "| length violation "
                           "after the frames | bend violation (rad) | hoses violating as laid out "
                           "| last frame's grabs |\n"
                           "|---|---|---|---|---|---|---|---|---|---|\n";
            for (int scale : quick ? std::vector<int>{1, 2} : std::vector<int>{1, 2, 4}) {
                const std::vector<Hose> fine = hosesAt(16 * scale, 8);
                for (int sides : {8, 16}) {
                    const std::vector<Hose> hoses = hosesAt(scale, sides);
                    double error = 0.0, radius = 0.0;
                    int points = 0;
                    for (size_t h = 0; h < hoses.size(); ++h) {
                        const std::vector<Vec3> coarse = hoses[h].points(),
                                                reference = fine[h].points();
                        points += static_cast<int>(coarse.size());
                        auto distance = [&](const Vec3& p) {
                            double best = 1e300;
                            for (size_t k = 0; k + 1 < reference.size(); ++k) {
                                const Vec3 d = reference[k + 1] - reference[k];
                                const double t = std::clamp(
                                    (p - reference[k]).dot(d) / d.squaredNorm(), 0.0, 1.0);
                                best = std::min(best, (p - reference[k] - t * d).norm());
                            }
                            return best;
                        };
                        for (size_t k = 0; k < coarse.size(); ++k) {
                            error = std::max(error, distance(coarse[k]));
                            if (k + 1 < coarse.size())
                                error =
                                    std::max(error, distance(0.5 * (coarse[k] + coarse[k + 1])));
                        }
                        radius = std::max(radius, 0.5 * engineProject.hoses[h].outerDiameter);
                    }
                    int violatingAsLaid = 0;
                    for (const Hose& hose : hoses) {
                        const UpdateResult v = hose.measureViolation();
                        if (v.lengthViolation > 1e-9 || v.angleViolation > 1e-9) ++violatingAsLaid;
                    }
                    std::map<std::string, int> statuses; // of the last frame's grabs
                    Scene scene;
                    std::vector<Vec3> laid;
                    for (const Hose& hose : hoses) {
                        laid.push_back(hose.points()[hose.points().size() / 2]);
                        scene.addHose(hose);
                    }
                    scene.updateSurfaces();
                    const int frames = quick ? 10 : 40, rounds = quick ? 1 : 2;
                    double best = 1e300;
                    for (int round = 0; round < rounds; ++round) {
                        const auto start = std::chrono::steady_clock::now();
                        for (int f = 0; f < frames; ++f) {
                            const double phase = 2 * std::numbers::pi * (f + 1) / frames;
                            for (int i = 0; i < scene.hoseCount(); ++i) {
                                const int middle = scene.hose(i).pointCount() / 2;
                                if (scene.hose(i).isFixed(middle)) continue;
                                const UpdateResult r =
                                    scene.hose(i).grab(middle, laid[static_cast<size_t>(i)] +
                                                                   0.02 * Vec3(std::cos(phase) - 1,
                                                                               std::sin(phase), 0));
                                if (f + 1 == frames && round + 1 == rounds)
                                    ++statuses[toString(r.status)];
                            }
                            scene.updateSurfaces();
                        }
                        best = std::min(best, 1e6 *
                                                  std::chrono::duration<double>(
                                                      std::chrono::steady_clock::now() - start)
                                                      .count() /
                                                  frames);
                    }
                    double lengthViolation = 0.0, bendViolation = 0.0;
                    for (int i = 0; i < scene.hoseCount(); ++i) {
                        const UpdateResult v = scene.hose(i).measureViolation();
                        lengthViolation = std::max(lengthViolation, v.lengthViolation);
                        bendViolation = std::max(bendViolation, v.angleViolation);
                    }
                    engineTable << "| "
                                << (scale == 1 ? std::string("as authored")
                                               : std::to_string(scale) + "x")
                                << " | " << points << " | " << sides << " | " << fmt(best) << " | "
                                << fmt(error) << " | "
                                << fmt(error + radius * (1 - std::cos(std::numbers::pi / sides)))
                                << " | " << fmt(lengthViolation) << " | " << fmt(bendViolation)
                                << " | " << violatingAsLaid << " |";
                    for (const auto& [status, count] : statuses)
                        engineTable << " " << status << " " << count;
                    engineTable << " |\n";
                    engineErrors.push_back(error);
                    engineErrors.push_back(best);
                }
            }
        } else {
            pipelineTable << "Skipped: " << engine.string() << " is absent.\n";
            engineTable << "Skipped: " << engine.string() << " is absent.\n";
        }
    }
#else
    pipelineTable << "Skipped: built without the exporter.\n";
    engineTable << "Skipped: built without the exporter.\n";
#endif

    // Cost of each feature beyond the paper, in this build. A feature whose switch
    // exists but changes nothing yet is reported as such, never with a cost of zero.
    std::ostringstream featureTable;
    std::vector<double> featureFigures;
    {
        const int frames = quick ? 50 : 400, rounds = quick ? 1 : 5;
        const auto none = [](HoseSpec&) {};
        const FeatureRun base = featureFrame(none, {}, false, frames, rounds);
        const FeatureRun baseRoll = featureFrame(none, {}, true, frames, rounds);
        featureTable << "| feature | µs per frame without | with | extra | effect in this build "
                        "|\n|---|---|---|---|---|\n";
        auto row = [&](const std::string& name, const FeatureRun& without, const FeatureRun& with,
                       const std::string& note, bool mustChange = true) {
            bool changed = !mustChange || with.positions.size() != without.positions.size();
            for (size_t i = 0; !changed && i < with.positions.size(); ++i)
                changed = with.positions[i] != without.positions[i];
            featureFigures.push_back(with.microseconds);
            featureTable << "| " << name << " | " << fmt(without.microseconds) << " | ";
            if (changed)
                featureTable << fmt(with.microseconds) << " | "
                             << fmt(with.microseconds - without.microseconds) << " ("
                             << fmt(100.0 * (with.microseconds / without.microseconds - 1.0))
                             << " %) | " << note << " |\n";
            else
                featureTable << "— | — | switched on it changes no vertex: not implemented in lib/ "
                                "at the time of this run |\n";
        };
        row("per-frame gravity (HoseSpec::gravity, one Hose::step() a frame)", base,
            featureFrame([](HoseSpec& spec) { spec.gravity.enabled = true; }, {}, false, frames,
                         rounds),
            "the hose sags while dragged; every constraint exact after each frame");
        row("torsion (HoseSpec::torsion), clamp turned a quarter turn", baseRoll,
            featureFrame([](HoseSpec& spec) { spec.torsion.enabled = true; }, {}, true, frames,
                         rounds),
            "rings roll with the clamp (the free end rolls rigidly)");
        // Collision: a floor of 2 × 150 × 150 = 45,000 triangles under the hose. Pressed: the floor
        // 1 cm below the hose's lowest surface point, so the circle's lower half pushes the hose
        // into it (contacts every other frame); apart: the same floor 1 m lower (BVH queries only).
        auto floorAt = [](double y) {
            std::vector<Vec3> positions;
            std::vector<std::uint32_t> indices;
            const int cells = 150;
            for (int i = 0; i <= cells; ++i)
                for (int k = 0; k <= cells; ++k)
                    positions.emplace_back(-0.2 + 1.2 * i / cells, y, -0.6 + 1.2 * k / cells);
            for (int i = 0; i < cells; ++i)
                for (int k = 0; k < cells; ++k) {
                    const std::uint32_t a = static_cast<std::uint32_t>(i * (cells + 1) + k),
                                        b = a + cells + 1;
                    indices.insert(indices.end(), {a, b, a + 1, a + 1, b, b + 1});
                }
            return MeshCollider::fromArrays(positions, indices);
        };
        double lowest = 0.0;
        for (const Vec3& p : base.axis)
            lowest = std::min(lowest, p.y());
        const std::shared_ptr<MeshCollider> pressed = floorAt(lowest - kHoseRadius - 0.01),
                                            apart = floorAt(lowest - 1.0);
        row("collision, 45,000-triangle floor the drag presses the hose into", base,
            featureFrame(
                none, [&](Hose& hose) { hose.setColliders({pressed}); }, false, frames, rounds),
            "the hose stays on the floor (continuous sweeps, contacts as projection rows)");
        row("collision, the same floor 1 m away (no contact)", base,
            featureFrame(
                none, [&](Hose& hose) { hose.setColliders({apart}); }, false, frames, rounds),
            "bounding-volume queries only", false);
    }

    // What the quick run can honestly check: the references match their closed forms (the
    // issue's catenary sags; the taut span is exactly as long as the hose and ends at its apex)
    // and every measured number is finite. Never speed.
    std::vector<std::string> failures;
    for (const auto& [length, expected] :
         {std::pair{1.05, 0.13930}, std::pair{1.2, 0.29234}, std::pair{2.0, 0.79639}})
        if (!(std::abs(Catenary::solve(length).sag() - expected) < 1e-5))
            failures.push_back("catenary reference: sag for length " + fmt(length) + " is " +
                               fmt(Catenary::solve(length).sag(), 6) + ", expected " +
                               fmt(expected, 6));
    {
        const TautSpan& taut = tautSpan();
        const double length = taut.tangentLength + kBendRadius * taut.lineAngle;
        const Vec3 apex = taut.point(taut.halfLength);
        if (!(std::abs(length - taut.halfLength) < 1e-9) ||
            !((apex - Vec3(0.5 * taut.span, taut.apexHeight, 0.0)).norm() < 1e-9))
            failures.push_back("taut-span reference: half length " + fmt(length, 12) +
                               " (expected 0.5), apex off by " +
                               fmt((apex - Vec3(0.5 * taut.span, taut.apexHeight, 0.0)).norm()));
        if (!((hairpinPoint(Vec3::Zero(), 0.0, 1.0) - Vec3::Zero()).norm() < 1e-12))
            failures.push_back("hairpin reference: the apex is not the pulled point");
    }
    for (const Row& r : rows)
        if (!std::isfinite(r.microseconds) || !std::isfinite(r.centreline) ||
            !std::isfinite(r.violation.stretchPercent))
            failures.push_back("non-finite figure: " + r.scenario + ", " + r.solver + ", " +
                               std::to_string(r.segments) + " segments");
    for (double figure : featureFigures)
        if (!std::isfinite(figure)) failures.push_back("non-finite figure in the feature table");
    for (double figure : engineErrors)
        if (!std::isfinite(figure)) failures.push_back("non-finite figure in the engine table");
    for (const Front::Point& p : catenaryChainTube)
        if (!std::isfinite(p.error) || !std::isfinite(p.time))
            failures.push_back("non-finite catenary figure: ChainTube, " + p.label);

    // --- outputs ----------------------------------------------------------------------------
    std::map<std::string, int> framesOf;
    for (const Scenario& scenario : scenarios())
        framesOf[scenario.name] = scenario.frames;
    std::ostringstream csv;
    csv << "scenario,solver,segments,ring_sides,microseconds_per_update,centreline_error_m,surface_"
           "error_m,"
           "max_stretch_percent,bend_excess_rad,self_intersecting_segments,frames,centreline_error_"
           "best_repeat_m\n";
    for (const Row& r : rows)
        csv << r.scenario << "," << r.solver << "," << r.segments << "," << r.sides << ","
            << r.microseconds << "," << r.centreline << "," << r.surface << ","
            << r.violation.stretchPercent << "," << r.violation.bendExcess << ","
            << r.violation.selfIntersections << "," << framesOf[r.scenario] << ","
            << r.bestCentreline << "\n";
    csv << catenaryCsv.str();

    std::ostringstream md;
    md << "# Speed against error\n\n"
       << (quick ? "Quick run (`--quick`): fewer resolutions and one repeat.\n\n" : "Full run.\n\n")
       << provenance << "Load average (1 min, /proc/loadavg) at the start " << loadAtStart
       << ", at the end of the measurements " << loadAverage()
       << ": other processes shared the machine, so timings are the best of repeats and carry "
          "noise.\n\n"
       << "Time per update is the best of the repeats, one core (other builds were loading the "
          "machine's second "
          "core). In the tables ChainTube's time includes its surface (rings + normals) at the "
          "ring sides shown; "
          "speed at equal error compares solver time only (the peers make no surface). Every "
          "scenario has one "
          "reference common to all solvers, a closed-form shape (named in each section with why it "
          "is the "
          "right one); the centreline error is the largest distance of an axis point from the "
          "reference point "
          "at the same rest arclength (so stretch counts as error); each repeat perturbs every "
          "target and moved "
          "frame by a few units in the last place (x (1 + r 1e-15), repeat r), and the error shown "
          "is the largest "
          "of the repeats (the best repeat's beside it: where they differ, the result depends on "
          "rounding). "
          "Surface error bound = centreline error + "
          "r(1 - cos(pi/N)). Equal error: each solver's runs form a front (the fastest run "
          "reaching each error); "
          "ChainTube's time at a peer's error is interpolated on its front linearly in "
          "log(error)/log(time) "
          "between the two runs around it, so the ratio compares runs of the same report.\n\n"
          "Peers: an XPBD rod (hard constraints: stretch band per segment, bend limit as a minimum "
          "distance of a "
          "joint's neighbours; quasi-static, no inertia, 1/4/16/64 Gauss-Seidel sweeps per frame) "
          "and Bullet's "
          "soft-body rope (btSoftBodyHelpers::CreateRope, one stepSimulation(1/60 s) per frame, "
          "4/16/64 position "
          "iterations, distance-2 bending links of stiffness "
       << kBulletBendStiffness
       << "; Bullet has bending "
          "stiffness, no bend limit). Grabs in Bullet: the grabbed node becomes a zero-mass "
          "(kinematic) node "
          "placed at the target every frame and stays kinematic while grabbed (its mass given "
          "back after every step would leave Bullet's link constants stale, and the node would "
          "not pull its neighbours).\n\n";
    std::vector<std::pair<std::string, EqualErrorSummary>>
        xpbdSummaries,     // per scenario, against the best XPBD runs
        xpbdHoseSummaries; // the same, counting the runs within kHoseStretchPercent
    for (const Scenario& scenario : scenarios()) {
        md << "## " << scenario.name << "\n\n"
           << scenario.description << ".\n\nReference: " << scenario.reference << ".\n\n"
           << "| solver | segments | sides | µs/update | centreline error | (best repeat) | "
              "surface error | max stretch % | bend excess (rad) | ring crossings |\n"
           << "|---|---|---|---|---|---|---|---|---|---|\n";
        for (const Row& r : rows)
            if (r.scenario == scenario.name && r.sides == ringSides.back())
                md << "| " << r.solver << " | " << r.segments << " | " << r.sides << " | "
                   << fmt(r.microseconds) << " | " << fmt(r.centreline) << " | "
                   << fmt(r.bestCentreline) << " | " << fmt(r.surface) << " | "
                   << fmt(r.violation.stretchPercent) << " | " << fmt(r.violation.bendExcess)
                   << " | " << r.violation.selfIntersections << " |\n";
        const auto& runs = runsOf[scenario.name];
        const Front chaintube = Front::of(runs.at("ChainTube"));
        std::vector<std::pair<std::string, Front>> peerFronts;
        std::vector<Front::Point> xpbdAll, xpbdHose;
        for (const auto& [name, points] : runs) {
            if (name == "ChainTube") continue;
            peerFronts.emplace_back(name, Front::of(points));
            if (name.rfind("XPBD", 0) == 0)
                for (const Front::Point& p : points) {
                    xpbdAll.push_back({p.error, p.time, name + ", " + p.label, p.stretchPercent});
                    if (p.stretchPercent <= kHoseStretchPercent) xpbdHose.push_back(xpbdAll.back());
                }
        }
        md << "\nSpeed at equal centreline error (solver µs per update; each peer's front against "
              "ChainTube's):\n\n"
           << equalErrorTable(chaintube, peerFronts, "µs")
           << "\nAgainst the best XPBD run at each error (any "
           << "iteration count, any resolution):\n\n"
           << equalErrorTable(
                  chaintube, {{"XPBD (best)", Front::of(xpbdAll)}}, "µs",
                  &xpbdSummaries.emplace_back(scenario.name, EqualErrorSummary()).second)
           << "\nAgainst the best XPBD run at each error among those that keep every segment "
              "within "
           << kHoseStretchPercent << " % of its rest length:\n\n";
        EqualErrorSummary& hoseSummary =
            xpbdHoseSummaries.emplace_back(scenario.name, EqualErrorSummary()).second;
        if (xpbdHose.empty())
            md << "(none of the XPBD runs does)\n\n";
        else
            md << equalErrorTable(chaintube, {{kHosePeer, Front::of(xpbdHose)}}, "µs", &hoseSummary)
               << "\n";
        size_t colour = 0;
        std::vector<PlotSeries>& plot = scenarioPlots[scenario.name];
        for (const Peer& peer : peers) {
            PlotSeries series{peer.name, colours[colour++ % 9], {}, true};
            for (const Front::Point& p : runs.at(peer.name))
                series.points.emplace_back(p.error, p.time);
            plot.push_back(series);
        }
    }
    md << "## wrap (closed form): a hose laid round a cylinder, and resolution independence\n\n"
       << "Laid along a route round a cylinder of radius R = " << kWrapRadius
       << " m; the closed form is two lines "
          "and a semicircle of radius R. With the datasheet radius the error falls with resolution "
          "(the sagitta "
          "l^2/8R); with the paper's fixed angle per joint the hose bends ever tighter as it is "
          "refined and the "
          "error does not fall. (The peers do not lay out routes.)\n\n"
       << wrapTable.str();
    md << "\n## catenary (closed form): a hose hung between two pins\n\n"
       << "Reference: the catenary, span 1 m, pins at the same height, y = a cosh(x/a) + c with 2a "
          "sinh(1/2a) = L "
          "(the equilibrium of an inextensible chain under gravity; sag "
       << fmt(Catenary::solve(1.05).sag(), 5) << " / " << fmt(Catenary::solve(1.2).sag(), 5)
       << " / " << fmt(Catenary::solve(2.0).sag(), 5)
       << " m for L = 1.05 / 1.2 / 2 m). ChainTube: Hose::sag() to its tolerance, 64 segments:\n\n"
       << catenaryTable.str()
       << "\nAgainst the peers (L = 1.2 m, inextensible, no bend limit), all from the same V of "
          "two straight legs: "
          "a frame is one Hose::step() for ChainTube (the runtime's per-frame gravity call: one "
          "implicit step of 1/90 s, the "
          "velocity carried over from frame to frame), one step of 1/60 s with gravity 9.81 m/s² "
          "for XPBD "
          "(PBD with inertia, 2 % damping per frame) and Bullet (2 % damping, no bending links: "
          "the catenary has no "
          "bend limit). Error = largest distance of a point from the catenary point at the same "
          "rest arclength, "
          "after every frame up to 64, then 128, 256, … frames; time = the solver's time to get "
          "there (settle "
          "time, best of the repeats). Only "
          "states with less than a tenth of the starting V's error (the V's error is "
       << fmt(catenaryStartError) << " m) enter the equal-error comparison.\n\n"
       << catenaryPeers.str()
       << "\nSpeed at equal error (time to settle to the peer's error, µs, fronts over "
          "resolutions and frame counts):\n\n"
       << equalErrorTable(Front::of(catenaryChainTube), catenaryFronts, "µs") << "\n";
    {
        std::vector<Front::Point> xpbdAll;
        for (const auto& [name, front] : catenaryFronts)
            if (name.rfind("XPBD", 0) == 0)
                for (Front::Point p : front.points)
                    xpbdAll.push_back({p.error, p.time, name + ", " + p.label});
        std::ostringstream ignored;
        ignored << equalErrorTable(
            Front::of(catenaryChainTube), {{"XPBD (best)", Front::of(xpbdAll)}}, "µs",
            &xpbdSummaries.emplace_back("catenary (time to settle)", EqualErrorSummary()).second);
        ignored << equalErrorTable(
            Front::of(catenaryChainTube), {{kHosePeer, Front::of(catenaryXpbdHose)}}, "µs",
            &xpbdHoseSummaries.emplace_back("catenary (time to settle)", EqualErrorSummary())
                 .second);
    }
    {
        std::ostringstream summary;
        summary << "## Summary: ChainTube against the best XPBD run at equal centreline error\n\n"
                << "Per scenario, over the XPBD runs on its front (the fastest XPBD run, any "
                   "iteration count and "
                   "resolution, reaching each error): the range of \"ChainTube faster by\" (≥: "
                   "ChainTube's coarsest "
                   "run is already more accurate, so the ratio is a lower bound), and how many "
                   "XPBD runs are more "
                   "accurate than every ChainTube run. Details and Bullet in each section.\n\n"
                << "| scenario | XPBD front runs | ChainTube faster by | XPBD more accurate than "
                   "every ChainTube run | "
                   "best XPBD error (m) | best ChainTube error (m) |\n|---|---|---|---|---|---|\n";
        for (const auto& [name, sum] : xpbdSummaries) {
            summary << "| " << name << " | " << sum.compared + sum.moreAccurate << " | ";
            summary << ratioRange(sum);
            summary << " | " << sum.moreAccurate << " | " << fmt(sum.bestPeerError) << " | "
                    << fmt(sum.bestChainTubeError) << " |\n";
        }
        summary << "\nCounting only the XPBD runs that keep every segment within "
                << kHoseStretchPercent
                << " % of its rest length (the others stretch the hose by up to thousands of "
                   "percent; the sections list each run's stretch):\n\n"
                << "| scenario | XPBD front runs within " << kHoseStretchPercent
                << " % | ChainTube faster by | of those more accurate than every ChainTube run | "
                   "best of those, error (m) |\n|---|---|---|---|---|\n";
        for (const auto& [name, sum] : xpbdHoseSummaries) {
            summary << "| " << name << " | " << sum.compared + sum.moreAccurate << " | ";
            summary << ratioRange(sum);
            summary << " | " << sum.moreAccurate << " | "
                    << (sum.compared + sum.moreAccurate ? fmt(sum.bestPeerError) : "—") << " |\n";
        }
        summary << "\n";
        const std::string text = md.str();
        const size_t at = text.find("## drag-middle");
        md.str(text.substr(0, at) + summary.str() + text.substr(at));
        md.seekp(0, std::ios_base::end);
    }
    md << "\n## The 50-hose frame (50 × 100 points × 16-sided rings; axis, rings, normals; one "
          "core)\n\n"
       << "Hoses whose inputs did not change cost one revision compare; the bound is writing the "
          "frame's vertex "
          "bytes once.\n\n"
       << frameTable.str();
    md << "\n## The 50-hose engine sample (samples/engine-50-hoses.ctproj): error and time per "
          "resolution\n\n"
       << "A frame moves every hose's middle point on a 2 cm circle round where it was laid (the "
          "hoses are fixed "
          "to the engine's parts at both ends, so these are grabs between fixed runs) and updates "
          "every surface "
          "(axis, rings, normals). Error: the lay-out along the authored routes against the same "
          "routes laid out "
          "at 16x the resolution (whose own error is 1/256 of it, the sagitta l^2/8R): the largest "
          "distance of "
          "an axis point or segment midpoint from the fine polyline; surface bound = that + r(1 - "
          "cos(pi/N)). "
          "Violations: largest over the 50 hoses after the frames (length relative, bend in "
          "rad).\n\n"
       << engineTable.str();
    md << "\n## Import and export\n\n" << pipelineTable.str();
    md << "\n## Cost of the features beyond the paper\n\n"
       << "A 100-point hose (about 1.1 m laid in a U, the first segment clamped, the other end "
          "free, 16-sided rings), its middle point moved on a 2 cm "
          "circle every frame (grab + surface update), with and without the feature; for torsion "
          "the clamp "
          "also turns a quarter turn about the hose axis over the run, in both columns. Every "
          "frame calls Hose::step() (per-frame gravity; "
          "one comparison when gravity is off). Gravity's settle step for authoring (Hose::sag()) "
          "is timed in the "
          "catenary section. A switch that changes no vertex would be reported as not implemented, "
          "never as free.\n\n"
       << featureTable.str();
    md << "\n## Model only what a scene needs (min bend radius 0.1 m, radius " << kHoseRadius
       << " m)\n\n"
       << tolerances.str();

    writeFile(outDir / "report.md", md.str());
    writeFile(outDir / "report.csv", csv.str());
    std::vector<std::string> written = {(outDir / "report.md").string(),
                                        (outDir / "report.csv").string()};
    for (const auto& [name, plot] : scenarioPlots) {
        const std::filesystem::path file = outDir / ("speed-vs-error-" + name + ".svg");
        writeFile(file,
                  logLogPlotSvg(
                      name == "catenary"
                          ? std::string("catenary: time to settle against error (front over "
                                        "resolutions and frames)")
                          : name + ": time against centreline error (one point per resolution)",
                      "centreline error (m)",
                      name == "catenary" ? "time to settle (us)" : "solver time per update (us)",
                      plot));
        written.push_back(file.string());
    }
    writeFile(outDir / "convergence.svg",
              logLogPlotSvg("Wrap round a cylinder: error against resolution", "axis segments",
                            "centreline error (m)",
                            {{"min bend radius (ChainTube)", "#d62728", radiusConvergence, true},
                             {"fixed angle (paper)", "#1f77b4", angleConvergence, true}}));
    written.push_back((outDir / "convergence.svg").string());
    for (const std::string& failure : failures)
        std::cerr << "chaintube-bench-report: " << failure << "\n";
    if (!failures.empty()) return 1;
    std::cout << "wrote";
    for (const std::string& file : written)
        std::cout << " " << file;
    std::cout << "\n";
    return 0;
}
