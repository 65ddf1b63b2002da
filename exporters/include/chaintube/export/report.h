// ChainTube — the length and bill-of-materials report: per hose its material, cut length, slack
// over the shortest valid length, smallest bend radius against the limit, smallest clearance
// over the motions, attachments and clips; totals per material. Used by `chaintube report`,
// `chaintube export --report` and the Python module's chaintube.report() (the same function);
// the columns are in exporters/README.md, "Length and bill-of-materials reports".
#pragma once

#include "chaintube/export/sweep.h"
#include "chaintube/formats/project.h"

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace chaintube::exporting {

struct ReportOptions
{
    int steps = 20; ///< sweep steps each way (SweepOptions::steps), 1 … 100,000
    /// Metres ≥ 0 (SweepOptions::clearanceThreshold; also the length fit's).
    double clearanceThreshold = 0.0;
    /// Metres ≥ 0: objects farther than this from a hose at every step are not searched, and
    /// the hose's smallest clearance is reported as none (SweepOptions::reportDistance).
    double reportDistance = 0.05;
    /// Fit the length of every hose between fixed ends (fit_length.h) for its slack. Off: no
    /// shortest valid length and no slack (the fit is the costly part: up to 64 sweeps a hose).
    bool fitLength = true;
    double tolerance = 0.001; ///< metres > 0: the shortest valid length to within this
    /// Called with the fraction done of the current project (0 … 1); returning false cancels
    /// (throws formats::Cancelled).
    std::function<bool(double)> progress;
};

/// One hose of the report. Lengths in metres.
struct HoseReport
{
    std::string project; ///< the project file as given
    std::string hoseId;
    std::string hoseName;
    /// The preset's name, or "inline (expansion E, min bend radius R m)" / "inline (expansion E,
    /// deflection angle A rad)" for a material written in the hose.
    std::string material;
    double restLength = 0.0;        ///< formats::hoseLength
    double fittingsAllowance = 0.0; ///< HoseDefinition::fittingsAllowance, as authored
    double cutLength = 0.0;         ///< restLength + fittingsAllowance
    /// The shortest length valid over the motions (LengthFit::shortest), for a hose between
    /// fixed ends whose fit found a valid length; slack = restLength − shortest (negative: the
    /// hose is shorter than any valid length). Unset otherwise; fitNote then says why.
    std::optional<double> shortestValidLength;
    std::optional<double> slack;
    std::string fitNote; ///< "" when fitted; else "not between fixed ends", "not fitted", reason
    /// The smallest bend radius over the sweep (HoseSweep::smallestBendRadius); unset when the
    /// hose is straight at every step.
    std::optional<double> smallestBendRadius;
    double minBendRadius = 0.0; ///< the material's minimum bend radius (0: none or an angle limit)
    /// smallestBendRadius − minBendRadius (negative: below the limit); unset without either.
    std::optional<double> bendMargin;
    /// The smallest clearance (hose surface to a scene object, < 0 inside) over the sweep, where
    /// it occurs (object, axis point, world point on the hose) and the motion values there
    /// ("project pose" without motions, else "motion-id value unit; …"). Unset when no object
    /// came within ReportOptions::reportDistance.
    std::optional<double> smallestClearance;
    std::string clearanceObject; ///< "<scene id>:<node path>"
    int clearanceAxisPoint = -1;
    Vec3 clearancePoint = Vec3::Zero();
    std::string clearanceMotion;
    int attachments = 0;
    int clips = 0;
};

/// One line of the bill of materials: every hose of one material.
struct MaterialTotal
{
    std::string material; ///< as HoseReport::material
    int hoses = 0;
    double restLength = 0.0;        ///< summed
    double fittingsAllowance = 0.0; ///< summed
    double cutLength = 0.0;         ///< summed
};

struct LengthReport
{
    std::vector<std::string> projects;    ///< the project files, in report order
    std::vector<HoseReport> hoses;        ///< project order, then hose order
    std::vector<MaterialTotal> materials; ///< by material name
};

/// The totals per material of `hoses`, sorted by material name.
std::vector<MaterialTotal> materialTotals(const std::vector<HoseReport>& hoses);

/// The report of one project (`projectFile` resolves its scene paths and names it in the report;
/// the project need not be saved there). Imports its scenes, sweeps its motions (the project's
/// pose alone without motions: sweepMotions with measurePoseWithoutMotions) and fits the length
/// of every hose between fixed ends (fitLengths). Throws the formats errors (file, format,
/// path), InvalidArgument for options out of range, and formats::Cancelled.
LengthReport projectReport(const formats::Project& project,
                           const std::filesystem::path& projectFile,
                           const formats::NamedRoots& roots, const ReportOptions& options = {});

/// The project files a report argument names: a project file, or a folder (every *.ctproj
/// directly in it, sorted). Throws formats::FileError for a path that does not exist, a file
/// that is not a *.ctproj, or a folder without one.
std::vector<std::filesystem::path> reportSources(const std::filesystem::path& projectOrFolder);

/// Loads each project and reports them together (projectReport, then the totals over all of
/// them). Throws at the first project that fails, its error naming the file.
LengthReport reportProjects(const std::vector<std::filesystem::path>& projectFiles,
                            const formats::NamedRoots& roots, const ReportOptions& options = {});

enum class ReportFormat { Csv, Json, Markdown };

/// "csv", "json", "md" (or "markdown"). Throws InvalidArgument naming the expected values.
ReportFormat reportFormatFromName(const std::string& name);
/// "csv", "json" or "md": the file extension of the format.
const char* extensionOf(ReportFormat format);

/// The report as text: CSV (a header line, one row per hose, then one "total" row per
/// material), JSON ({"projects", "hoses", "materials"}; absent values as null) or Markdown (two
/// tables). Lengths in metres.
std::string formatReport(const LengthReport& report, ReportFormat format);

} // namespace chaintube::exporting
