// ChainTube — length fitting: for a hose between fixed ends, the range of lengths for which it
// stays valid over the whole motion sweep (sweep.h). Used by `chaintube check --fit-length` and
// the editor's "Fit length" (the same function); the rules are in exporters/README.md, "Length
// fitting".
#pragma once

#include "chaintube/export/sweep.h"

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace chaintube::exporting {

struct LengthFitOptions
{
    int steps = 20;                  ///< sweep steps each way (SweepOptions::steps)
    double clearanceThreshold = 0.0; ///< metres ≥ 0 (SweepOptions::clearanceThreshold)
    double reportDistance = 0.05;    ///< metres ≥ 0 (SweepOptions::reportDistance)
    bool includeAttachedNodes = false;
    int gravityStepsPerStep = 30;
    /// Metres > 0: each end of the range is found to within this (the bisection stops when its
    /// bracket is no wider).
    double tolerance = 0.001;
    /// Relative ≥ 0: how much longer than its rest length the hose may be pulled between two
    /// held points (0: never; the material's stretch band is the model's compliance, not an
    /// allowance for a design length).
    double stretchAllowance = 0.0;
    /// ≥ 1: the longest length searched is this times the shortest valid one; a hose valid
    /// there reports that length with LengthFit::longestAtSearchLimit.
    double searchLimitFactor = 2.0;
    /// ≥ 4: at most this many sweeps per hose (bounds the work; a search cut short keeps a
    /// valid end of its bracket and sets LengthFit::converged false).
    int maxSweepsPerHose = 64;
    /// Called with the fraction done (0 … 1); returning false cancels (throws
    /// formats::Cancelled).
    std::function<bool(double)> progress;
};

/// What limits a length at one end of the range.
enum class LengthLimit {
    None,      ///< not limited (the search limit, or no failure seen)
    Taut,      ///< pulled longer than its rest length between two held points
    Stretch,   ///< a segment beyond the stretch band
    Reach,     ///< an attachment beyond the hose's reach
    Bend,      ///< a joint beyond its bend limit (or the hose cannot be laid through a clip)
    Clearance, ///< an object nearer than the clearance threshold (or a collision)
};

/// "none", "taut", "stretch", "reach", "bend", "clearance".
const char* toString(LengthLimit limit);

/// The fitted range of one hose. Lengths in metres.
struct LengthFit
{
    int hose = -1; ///< index in project.hoses
    std::string hoseId;
    double currentLength = 0.0; ///< formats::hoseLength of the definition as given
    /// True when some length is valid: then shortest ≤ longest, both checked by a sweep.
    bool valid = false;
    double shortest = 0.0;             ///< the shortest valid length found (within the tolerance)
    double longest = 0.0;              ///< the longest valid length found (within the tolerance)
    bool longestAtSearchLimit = false; ///< valid up to searchLimitFactor × shortest
    /// Below `shortest` (by more than the tolerance) the hose breaks this limit; above
    /// `longest` that one (None at the search limit). When !valid, `invalidBy` is what broke
    /// at the last length tried and `reason` says it in words.
    LengthLimit shortestLimit = LengthLimit::None;
    LengthLimit longestLimit = LengthLimit::None;
    LengthLimit invalidBy = LengthLimit::None;
    /// The object that limits the longest length (or made every length invalid): scene id and
    /// path, its distance at the first length beyond the range (metres).
    std::string limitingObject;
    double limitingDistance = 0.0;
    /// The largest path between two consecutive attachments over the sweep (their chord, or
    /// through the centres of the clips between them) divided by the share of the length
    /// between them: below this the hose is taut somewhere (metres).
    double tautBound = 0.0;
    bool currentValid = false; ///< the current length lies in the range
    bool converged = true;     ///< false: the sweep budget ran out before the tolerance
    int sweeps = 0;            ///< sweeps run
    std::string reason;        ///< why no length is valid ("" when valid)
};

struct LengthFitReport
{
    std::vector<formats::PartMotion> motions; ///< empty: fitted over the project's pose alone
    int sweptSteps = 0;                       ///< steps of each sweep (1 without motions)
    double tolerance = 0.0;
    double clearanceThreshold = 0.0;
    std::vector<LengthFit> hoses; ///< the hoses fitted, project order
    bool allValid() const
    {
        for (const LengthFit& fit : hoses)
            if (!fit.valid) return false;
        return true;
    }
};

/// True when the hose's first and last axis points are held by attachments and some point
/// between them is free (the hoses length fitting applies to). The point count is the one its
/// length gives (formats::hoseLength with its resolution).
bool betweenFixedEnds(const formats::Project& project, const formats::HoseDefinition& hose);

/// Fits the length of hose `hoseIndex` of the project (`scenes` at their file pose). A length
/// is applied as formats::withLength applies it (the hose re-laid where it lies with that rest
/// length, its attachments kept, laid through its clips where they are, their places scaled or
/// slid) and the project's motions are swept with that hose alone (sweepMotions, which carries
/// the clips with their parts; without motions its pose is measured once). A length is valid
/// when over every step the hose is never pulled longer than its rest length
/// (× 1 + stretchAllowance) between two held points (attachments and clips) nor between two
/// attachments along the path through the clips between them, no segment leaves its band, no
/// attachment or clip is beyond reach, no joint bends beyond its limit, the hose passes through
/// every clip, and no object comes nearer than the clearance threshold. The shortest
/// valid length is searched upward from the taut bound, the longest from the shortest up to
/// searchLimitFactor × shortest, each by bisection to the tolerance; validity is assumed to
/// change once across each end (too short below, too long above). Throws InvalidArgument for
/// an index out of range, a hose not between fixed ends or options out of range, the errors
/// of sweepMotions, and formats::Cancelled.
LengthFit fitHoseLength(const formats::Project& project, const formats::ImportedScenes& scenes,
                        int hoseIndex, const LengthFitOptions& options);

/// fitHoseLength for the hoses named by id (empty: every hose between fixed ends), project
/// order, progress over all of them. Throws InvalidArgument naming an unknown id or a hose not
/// between fixed ends.
LengthFitReport fitLengths(const formats::Project& project, const formats::ImportedScenes& scenes,
                           const std::vector<std::string>& hoseIds,
                           const LengthFitOptions& options);

/// Loads the project, imports its scenes and fits (the whole of `chaintube check
/// --fit-length`). Throws the formats errors (file, format, path) and as fitLengths.
LengthFitReport fitProjectLengths(const std::filesystem::path& projectFile,
                                  const formats::NamedRoots& roots,
                                  const std::vector<std::string>& hoseIds,
                                  const LengthFitOptions& options);

/// The report as JSON text (the fields: exporters/README.md, "Length fitting").
std::string lengthFitJson(const LengthFitReport& report, const std::string& projectFile);

} // namespace chaintube::exporting
