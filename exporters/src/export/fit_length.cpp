// Length fitting: the range of lengths for which a hose between fixed ends stays valid over the
// motion sweep, each end found by bisection over sweeps.
#include "chaintube/export/fit_length.h"

#include "chaintube/formats/errors.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

namespace chaintube::exporting {

namespace {

/// A taut span counts from this relative excess on (the solver holds lengths to 1e-9).
constexpr double kTautTolerance = 1e-9;
/// A trial hose whose clip centre is farther than this (relative to its length) from where the
/// clip is passes beside the clip (formats::withLength could not lay it through).
constexpr double kClipMissTolerance = 1e-6;

void validate(const LengthFitOptions& options)
{
    if (!(options.tolerance > 0.0) || !std::isfinite(options.tolerance))
        throw InvalidArgument("length fit tolerance: expected a length > 0 metres, got " +
                              std::to_string(options.tolerance));
    if (!(options.stretchAllowance >= 0.0) || !std::isfinite(options.stretchAllowance))
        throw InvalidArgument("length fit stretch allowance: expected a finite ratio >= 0, got " +
                              std::to_string(options.stretchAllowance));
    if (!(options.searchLimitFactor >= 1.0) || !std::isfinite(options.searchLimitFactor))
        throw InvalidArgument("length fit search limit: expected a finite factor >= 1, got " +
                              std::to_string(options.searchLimitFactor));
    if (options.maxSweepsPerHose < 4)
        throw InvalidArgument("length fit sweeps: expected at least 4 a hose, got " +
                              std::to_string(options.maxSweepsPerHose));
}

/// One length tried: what its sweep showed.
struct Trial
{
    double length = 0.0;
    LengthLimit tooShort = LengthLimit::None; ///< the first short-side limit broken
    LengthLimit tooLong = LengthLimit::None;  ///< Clearance or None
    double tautBound = 0.0;                   ///< as LengthFit::tautBound
    bool missesAClip = false;                 ///< the hose is not laid through every clip
    std::string object;                       ///< the nearest object below the threshold
    double objectDistance = 0.0;
    bool valid() const { return tooShort == LengthLimit::None && tooLong == LengthLimit::None; }
    LengthLimit failure() const { return tooShort != LengthLimit::None ? tooShort : tooLong; }
};

/// Runs the sweeps of one hose, counting them and reporting progress.
class Fitter
{
public:
    Fitter(const formats::Project& project, const formats::ImportedScenes& scenes, int hoseIndex,
           const LengthFitOptions& options, std::function<bool(double)> progress)
        : m_project(project), m_scenes(scenes),
          m_definition(project.hoses.at(static_cast<size_t>(hoseIndex))), m_options(options),
          m_progress(std::move(progress))
    {
        m_single = project;
        m_single.hoses.clear();
        // Where each clip holds the hose, in the clip's frame (its part carries it): a trial
        // length must pass there.
        if (!m_definition.clips.empty()) {
            const Hose reference = formats::buildHose(project, m_definition, scenes);
            const size_t attachments = m_definition.attachments.size();
            for (size_t c = 0; c < m_definition.clips.size(); ++c)
                m_clipCentres.push_back(reference.attachments()[attachments + c].clipCentre);
        }
        const double currentLength = formats::hoseLength(project, m_definition);
        m_expectedSweeps =
            4.0 + 2.0 * std::ceil(std::log2(std::max(
                            2.0, currentLength * options.searchLimitFactor / options.tolerance)));
    }

    int sweeps() const { return m_sweeps; }
    bool budgetLeft() const { return m_sweeps < m_options.maxSweepsPerHose; }

    Trial evaluate(double length)
    {
        Trial trial;
        trial.length = length;
        m_single.hoses = {formats::withLength(m_project, m_definition, m_scenes, length)};
        SweepOptions sweep;
        sweep.steps = m_options.steps;
        sweep.clearanceThreshold = m_options.clearanceThreshold;
        sweep.reportDistance = m_options.reportDistance;
        sweep.includeAttachedNodes = m_options.includeAttachedNodes;
        sweep.gravityStepsPerStep = m_options.gravityStepsPerStep;
        sweep.measurePoseWithoutMotions = true;
        const double done = m_sweeps;
        sweep.progress = [&](double fraction) { return report(done + fraction); };
        double tautExcess = 0.0;
        sweep.onStep = [&](int step, const std::vector<Hose>& hoses) {
            measureTaut(hoses.front(), tautExcess, trial.tautBound);
            if (step == 0) trial.missesAClip = missesAClip(hoses.front(), length);
        };
        const SweepReport swept = sweepMotions(m_single, m_scenes, sweep);
        ++m_sweeps;
        const HoseSweep& hose = swept.hoses.front();
        if (tautExcess > m_options.stretchAllowance + kTautTolerance)
            trial.tooShort = LengthLimit::Taut;
        else if (hose.overstretched())
            trial.tooShort = LengthLimit::Stretch;
        else if (hose.beyondReach())
            trial.tooShort = LengthLimit::Reach;
        else if (hose.bendViolated() || trial.missesAClip)
            trial.tooShort = LengthLimit::Bend;
        for (const ObjectSweep& object : hose.objects) // nearest first
            if (object.stepsBelowThreshold > 0 || object.collides()) {
                trial.tooLong = LengthLimit::Clearance;
                trial.object = object.sceneId + ":" + object.objectPath;
                trial.objectDistance = object.minDistance;
                break;
            }
        return trial;
    }

    bool report(double sweepsDone)
    {
        if (!m_progress) return true;
        return m_progress(std::min(0.99, sweepsDone / m_expectedSweeps));
    }

private:
    /// The taut measure (the excess is the largest relative excess, the bound the largest taut
    /// bound, over the steps):
    ///  * for every pair of consecutive held runs, attachments and clips, in axis order: the
    ///    chord between the last held point of one and the first of the next where their frames
    ///    put them, against the rest length between those points (the excess);
    ///  * for every pair of consecutive attachments: the path from one to the next through the
    ///    centres of the clips between them, against the rest length between the attachments
    ///    (the excess, and the bound: however the hose slides through the clips, it needs that
    ///    path's share of the length).
    void measureTaut(const Hose& hose, double& excess, double& bound) const
    {
        struct Held
        {
            const Hose::Attachment* run;
            Vec3 centre; ///< a clip's centre (world)
        };
        std::vector<Held> held;
        const size_t attachments = m_definition.attachments.size();
        for (size_t a = 0; a < hose.attachments().size(); ++a) {
            const Hose::Attachment& run = hose.attachments()[a];
            const bool clip =
                run.isClip() && a >= attachments && a - attachments < m_clipCentres.size();
            held.push_back(
                {&run, clip ? run.frame.apply(m_clipCentres[a - attachments]) : Vec3::Zero()});
        }
        std::sort(held.begin(), held.end(),
                  [](const Held& a, const Held& b) { return a.run->first < b.run->first; });
        const double total = hose.restLengthTotal();
        const auto restBetween = [&](int from, int to) {
            double rest = 0.0;
            for (int s = from; s < to; ++s)
                rest += hose.restLength(s);
            return rest;
        };
        for (size_t a = 0; a + 1 < held.size(); ++a) {
            const Hose::Attachment& from = *held[a].run;
            const Hose::Attachment& to = *held[a + 1].run;
            if (to.first <= from.last) continue;
            const Vec3 start = from.frame.apply(from.localPoints.back());
            const Vec3 end = to.frame.apply(to.localPoints.front());
            excess =
                std::max(excess, (end - start).norm() / restBetween(from.last, to.first) - 1.0);
        }
        for (size_t a = 0; a < held.size(); ++a) {
            if (held[a].run->isClip()) continue;
            size_t b = a + 1;
            while (b < held.size() && held[b].run->isClip())
                ++b;
            if (b == held.size()) break;
            const Hose::Attachment& from = *held[a].run;
            const Hose::Attachment& to = *held[b].run;
            if (to.first <= from.last) continue;
            Vec3 at = from.frame.apply(from.localPoints.back());
            double path = 0.0;
            for (size_t c = a + 1; c < b; ++c) {
                path += (held[c].centre - at).norm();
                at = held[c].centre;
            }
            path += (to.frame.apply(to.localPoints.front()) - at).norm();
            const double rest = restBetween(from.last, to.first);
            excess = std::max(excess, path / rest - 1.0);
            bound = std::max(bound, path / rest * total / (1.0 + m_options.stretchAllowance));
        }
    }

    /// Whether a clip of the trial hose holds it elsewhere than the clip is (its centre in the
    /// clip's frame moved): the length could not be laid through the clip.
    bool missesAClip(const Hose& hose, double length) const
    {
        const size_t attachments = m_definition.attachments.size();
        for (size_t c = 0; c < m_clipCentres.size(); ++c) {
            const size_t a = attachments + c;
            if (a >= hose.attachments().size() ||
                (hose.attachments()[a].clipCentre - m_clipCentres[c]).norm() >
                    kClipMissTolerance * length)
                return true;
        }
        return false;
    }

    const formats::Project& m_project;
    const formats::ImportedScenes& m_scenes;
    const formats::HoseDefinition& m_definition;
    const LengthFitOptions& m_options;
    std::function<bool(double)> m_progress;
    formats::Project m_single;       ///< the project with the trial hose alone
    std::vector<Vec3> m_clipCentres; ///< each clip's centre in its frame, as the hose is built
    int m_sweeps = 0;
    double m_expectedSweeps = 1.0;
};

std::string metres(double value)
{
    std::ostringstream text;
    text.precision(4);
    text << value << " m";
    return text.str();
}

std::string describe(LengthLimit limit)
{
    switch (limit) {
    case LengthLimit::None:
        return "no limit";
    case LengthLimit::Taut:
        return "is pulled longer than its rest length between its held points";
    case LengthLimit::Stretch:
        return "stretches a segment beyond its band";
    case LengthLimit::Reach:
        return "cannot reach an attachment";
    case LengthLimit::Bend:
        return "bends a joint beyond its limit (or cannot be laid through a clip within it)";
    case LengthLimit::Clearance:
        return "comes nearer to an object than the clearance";
    }
    return "?";
}

} // namespace

const char* toString(LengthLimit limit)
{
    switch (limit) {
    case LengthLimit::None:
        return "none";
    case LengthLimit::Taut:
        return "taut";
    case LengthLimit::Stretch:
        return "stretch";
    case LengthLimit::Reach:
        return "reach";
    case LengthLimit::Bend:
        return "bend";
    case LengthLimit::Clearance:
        return "clearance";
    }
    return "?";
}

bool betweenFixedEnds(const formats::Project& project, const formats::HoseDefinition& hose)
{
    const double count = hose.segmentCount > 0
                             ? hose.segmentCount
                             : std::round(formats::hoseLength(project, hose) / hose.segmentLength);
    const int lastPoint = static_cast<int>(std::clamp(count, 1.0, 1e6));
    std::vector<char> fixed(static_cast<size_t>(lastPoint) + 1, 0);
    for (const formats::HoseAttachment& attachment : hose.attachments)
        for (int p = std::max(0, attachment.firstPoint);
             p <= std::min(lastPoint, attachment.lastPoint); ++p)
            fixed[static_cast<size_t>(p)] = 1;
    return fixed.front() && fixed.back() && std::find(fixed.begin(), fixed.end(), 0) != fixed.end();
}

LengthFit fitHoseLength(const formats::Project& project, const formats::ImportedScenes& scenes,
                        int hoseIndex, const LengthFitOptions& options)
{
    validate(options);
    if (hoseIndex < 0 || hoseIndex >= static_cast<int>(project.hoses.size()))
        throw InvalidArgument("length fit: no hose " + std::to_string(hoseIndex) +
                              " (the project has " + std::to_string(project.hoses.size()) + ")");
    const formats::HoseDefinition& definition = project.hoses[static_cast<size_t>(hoseIndex)];
    LengthFit fit;
    fit.hose = hoseIndex;
    fit.hoseId = definition.id;
    fit.currentLength = formats::hoseLength(project, definition);
    if (!betweenFixedEnds(project, definition))
        throw InvalidArgument("hose '" + definition.id +
                              "': length fitting needs both ends held by attachments and a free "
                              "point between them");
    Fitter fitter(project, scenes, hoseIndex, options, options.progress);
    const auto bisect = [&](double& good, double& bad, Trial& goodTrial, Trial& badTrial,
                            const std::function<bool(const Trial&)>& passes) {
        while (std::abs(bad - good) > options.tolerance) {
            if (!fitter.budgetLeft()) {
                fit.converged = false;
                return;
            }
            const double middle = 0.5 * (good + bad);
            Trial trial = fitter.evaluate(middle);
            if (passes(trial))
                good = middle, goodTrial = std::move(trial);
            else
                bad = middle, badTrial = std::move(trial);
        }
    };
    const auto shortPasses = [](const Trial& t) { return t.tooShort == LengthLimit::None; };
    const auto passes = [](const Trial& t) { return t.valid(); };

    // The short end: below the taut bound the hose is taut at some step by definition, so the
    // search starts there and, when that fails for another limit, brackets upward.
    const Trial current = fitter.evaluate(fit.currentLength);
    fit.tautBound = current.tautBound;
    double low = std::max(current.tautBound, options.tolerance);
    Trial lowTrial = fitter.evaluate(low);
    Trial shortestTrial;
    if (shortPasses(lowTrial)) {
        fit.shortest = low;
        fit.shortestLimit = LengthLimit::Taut;
        shortestTrial = lowTrial;
    } else {
        const double searchLimit = std::max(fit.currentLength, low) * options.searchLimitFactor;
        double high = std::max(fit.currentLength, low);
        Trial highTrial = high == fit.currentLength ? current : fitter.evaluate(high);
        while (!shortPasses(highTrial) && high < searchLimit && fitter.budgetLeft()) {
            low = high, lowTrial = std::move(highTrial);
            high = std::min(searchLimit, high * 1.25);
            highTrial = fitter.evaluate(high);
        }
        if (!shortPasses(highTrial)) {
            fit.invalidBy = highTrial.tooShort;
            fit.sweeps = fitter.sweeps();
            fit.converged = high >= searchLimit;
            fit.reason = "at every length tried up to " + metres(high) + " the hose " +
                         describe(highTrial.tooShort);
            return fit;
        }
        bisect(high, low, highTrial, lowTrial, shortPasses);
        fit.shortest = high;
        fit.shortestLimit = lowTrial.tooShort;
        shortestTrial = highTrial;
    }
    if (!shortestTrial.valid()) {
        fit.invalidBy = shortestTrial.failure();
        fit.limitingObject = shortestTrial.object;
        fit.limitingDistance = shortestTrial.objectDistance;
        fit.sweeps = fitter.sweeps();
        fit.reason =
            "at its shortest length " + metres(fit.shortest) + " the hose already " +
            describe(shortestTrial.failure()) +
            (shortestTrial.object.empty() ? std::string()
                                          : " (" + shortestTrial.object + " at " +
                                                metres(shortestTrial.objectDistance) + ")") +
            "; a longer hose comes nearer";
        return fit;
    }
    fit.valid = true;

    // The long end: from the shortest (or the current length when valid and longer) up to the
    // search limit.
    const double searchLimit = fit.shortest * options.searchLimitFactor;
    double good = fit.shortest;
    Trial goodTrial = shortestTrial;
    if (current.valid() && fit.currentLength > good && fit.currentLength < searchLimit)
        good = fit.currentLength, goodTrial = current;
    Trial badTrial = fitter.evaluate(searchLimit);
    if (badTrial.valid()) {
        fit.longest = searchLimit;
        fit.longestAtSearchLimit = true;
    } else {
        double bad = searchLimit;
        bisect(good, bad, goodTrial, badTrial, passes);
        fit.longest = good;
        fit.longestLimit = badTrial.failure();
        fit.limitingObject = badTrial.object;
        fit.limitingDistance = badTrial.objectDistance;
    }
    fit.currentValid =
        fit.shortest <= fit.currentLength + 1e-12 && fit.currentLength <= fit.longest + 1e-12;
    fit.sweeps = fitter.sweeps();
    return fit;
}

LengthFitReport fitLengths(const formats::Project& project, const formats::ImportedScenes& scenes,
                           const std::vector<std::string>& hoseIds, const LengthFitOptions& options)
{
    validate(options);
    std::vector<int> chosen;
    for (const std::string& id : hoseIds) {
        const auto found =
            std::find_if(project.hoses.begin(), project.hoses.end(),
                         [&](const formats::HoseDefinition& hose) { return hose.id == id; });
        if (found == project.hoses.end()) {
            std::string known;
            for (const formats::HoseDefinition& hose : project.hoses)
                known += (known.empty() ? "" : ", ") + hose.id;
            throw InvalidArgument("no hose '" + id + "' in the project (hoses: " +
                                  (known.empty() ? std::string("none") : known) + ")");
        }
        if (!betweenFixedEnds(project, *found))
            throw InvalidArgument("hose '" + id +
                                  "': length fitting needs both ends held by attachments and a "
                                  "free point between them");
        chosen.push_back(static_cast<int>(found - project.hoses.begin()));
    }
    if (hoseIds.empty())
        for (size_t h = 0; h < project.hoses.size(); ++h)
            if (betweenFixedEnds(project, project.hoses[h])) chosen.push_back(static_cast<int>(h));
    std::sort(chosen.begin(), chosen.end());
    chosen.erase(std::unique(chosen.begin(), chosen.end()), chosen.end());

    LengthFitReport report;
    report.motions = project.motions;
    report.sweptSteps =
        project.motions.empty()
            ? 1
            : static_cast<int>(sweepSchedule(project.motions, std::max(1, options.steps)).size());
    report.tolerance = options.tolerance;
    report.clearanceThreshold = options.clearanceThreshold;
    double reported = 0.0;
    for (size_t i = 0; i < chosen.size(); ++i) {
        LengthFitOptions each = options;
        if (options.progress)
            each.progress = [&, i](double fraction) {
                reported = std::max(reported, (static_cast<double>(i) + fraction) /
                                                  static_cast<double>(chosen.size()));
                return options.progress(reported);
            };
        report.hoses.push_back(fitHoseLength(project, scenes, chosen[i], each));
    }
    if (options.progress) static_cast<void>(options.progress(1.0)); // done: nothing to cancel
    return report;
}

LengthFitReport fitProjectLengths(const std::filesystem::path& projectFile,
                                  const formats::NamedRoots& roots,
                                  const std::vector<std::string>& hoseIds,
                                  const LengthFitOptions& options)
{
    validate(options);
    formats::ProjectLoadOptions load;
    load.roots = roots;
    const formats::Project project = formats::loadProject(projectFile, load);
    const formats::ImportedScenes scenes =
        formats::importProjectScenes(project, projectFile, roots);
    return fitLengths(project, scenes, hoseIds, options);
}

std::string lengthFitJson(const LengthFitReport& report, const std::string& projectFile)
{
    using ordered = nlohmann::ordered_json;
    const auto lengthOrNull = [](bool present, double value) -> ordered {
        if (!present) return nullptr;
        return value;
    };
    ordered document = ordered::object();
    document["project"] = projectFile;
    document["allValid"] = report.allValid();
    ordered motions = ordered::array();
    for (const formats::PartMotion& motion : report.motions)
        motions.push_back(motion.id);
    document["motions"] = motions;
    document["sweptSteps"] = report.sweptSteps;
    document["tolerance"] = report.tolerance;
    document["clearanceThreshold"] = report.clearanceThreshold;
    ordered hoses = ordered::array();
    for (const LengthFit& fit : report.hoses) {
        ordered entry = ordered::object();
        entry["id"] = fit.hoseId;
        entry["length"] = fit.currentLength;
        entry["valid"] = fit.valid;
        entry["shortest"] = lengthOrNull(fit.valid, fit.shortest);
        entry["longest"] = lengthOrNull(fit.valid, fit.longest);
        entry["longestAtSearchLimit"] = fit.longestAtSearchLimit;
        entry["shortestLimit"] = toString(fit.shortestLimit);
        entry["longestLimit"] = toString(fit.longestLimit);
        entry["invalidBy"] = toString(fit.invalidBy);
        entry["limitingObject"] =
            fit.limitingObject.empty() ? ordered(nullptr) : ordered(fit.limitingObject);
        entry["limitingDistance"] = lengthOrNull(!fit.limitingObject.empty(), fit.limitingDistance);
        entry["tautBound"] = fit.tautBound;
        entry["currentValid"] = fit.currentValid;
        entry["converged"] = fit.converged;
        entry["sweeps"] = fit.sweeps;
        entry["reason"] = fit.reason.empty() ? ordered(nullptr) : ordered(fit.reason);
        hoses.push_back(entry);
    }
    document["hoses"] = hoses;
    return document.dump(2) + "\n";
}

} // namespace chaintube::exporting
