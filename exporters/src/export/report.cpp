#include "chaintube/export/report.h"

#include "chaintube/export/batch.h"
#include "chaintube/export/fit_length.h"
#include "chaintube/formats/errors.h"
#include "chaintube/formats/project_hoses.h"

#include <charconv>
#include <cmath>
#include <iomanip>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

namespace chaintube::exporting {

namespace fs = std::filesystem;

namespace {

std::string materialName(const formats::HoseDefinition& hose)
{
    if (const auto* preset = std::get_if<formats::PresetName>(&hose.material)) return preset->name;
    const Material& material = std::get<Material>(hose.material);
    std::ostringstream text;
    text << std::setprecision(6) << "inline (expansion " << material.expansionCoefficient;
    if (material.bendLimit.kind == BendLimit::Kind::MinBendRadius)
        text << ", min bend radius " << material.bendLimit.value << " m)";
    else
        text << ", deflection angle " << material.bendLimit.value << " rad)";
    return text.str();
}

/// "project pose", or "lever 0.48 rad; carriage 0.072 m" at a sweep step.
std::string motionAt(const SweepReport& sweep, int step)
{
    if (step < 0 || step >= static_cast<int>(sweep.steps.size()) || sweep.motions.empty())
        return "project pose";
    const SweepStep& at = sweep.steps[static_cast<size_t>(step)];
    std::ostringstream text;
    text << std::setprecision(6);
    for (size_t m = 0; m < sweep.motions.size(); ++m)
        text << (m ? "; " : "") << sweep.motions[m].id << " " << at.values[m]
             << (sweep.motions[m].kind == formats::PartMotion::Kind::Hinge ? " rad" : " m");
    return text.str();
}

/// Shortest round-trip decimal text of a finite double.
std::string number(double value)
{
    char buffer[32];
    const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
    return std::string(buffer, result.ptr);
}

std::string optionalNumber(const std::optional<double>& value)
{
    return value ? number(*value) : std::string();
}

std::string csvField(const std::string& text)
{
    if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
    std::string quoted = "\"";
    for (const char c : text) {
        if (c == '"') quoted += '"';
        quoted += c;
    }
    return quoted + "\"";
}

/// Markdown table cell: metres with 4 decimals (0.1 mm), "–" when absent.
std::string metres(const std::optional<double>& value)
{
    if (!value) return "–";
    std::ostringstream text;
    text << std::fixed << std::setprecision(4) << *value;
    return text.str();
}

std::string markdownCell(const std::string& text)
{
    std::string escaped;
    for (const char c : text) {
        if (c == '|') escaped += '\\';
        escaped += c == '\n' ? ' ' : c;
    }
    return escaped.empty() ? "–" : escaped;
}

std::string csvText(const LengthReport& report)
{
    std::ostringstream out;
    out << "kind,project,hose,name,material,count,rest_length_m,fittings_allowance_m,cut_length_m,"
           "shortest_valid_length_m,slack_m,fit_note,smallest_bend_radius_m,min_bend_radius_m,"
           "bend_margin_m,smallest_clearance_m,clearance_object,clearance_axis_point,"
           "clearance_x_m,clearance_y_m,clearance_z_m,clearance_motion,attachments,clips\n";
    for (const HoseReport& hose : report.hoses) {
        out << "hose," << csvField(hose.project) << "," << csvField(hose.hoseId) << ","
            << csvField(hose.hoseName) << "," << csvField(hose.material) << ",1,"
            << number(hose.restLength) << "," << number(hose.fittingsAllowance) << ","
            << number(hose.cutLength) << "," << optionalNumber(hose.shortestValidLength) << ","
            << optionalNumber(hose.slack) << "," << csvField(hose.fitNote) << ","
            << optionalNumber(hose.smallestBendRadius) << ","
            << (hose.minBendRadius > 0.0 ? number(hose.minBendRadius) : std::string()) << ","
            << optionalNumber(hose.bendMargin) << "," << optionalNumber(hose.smallestClearance)
            << ",";
        if (hose.smallestClearance)
            out << csvField(hose.clearanceObject) << "," << hose.clearanceAxisPoint << ","
                << number(hose.clearancePoint.x()) << "," << number(hose.clearancePoint.y()) << ","
                << number(hose.clearancePoint.z()) << "," << csvField(hose.clearanceMotion);
        else
            out << ",,,,,";
        out << "," << hose.attachments << "," << hose.clips << "\n";
    }
    for (const MaterialTotal& total : report.materials)
        out << "total,,,," << csvField(total.material) << "," << total.hoses << ","
            << number(total.restLength) << "," << number(total.fittingsAllowance) << ","
            << number(total.cutLength) << ",,,,,,,,,,,,,,,\n";
    return out.str();
}

std::string jsonText(const LengthReport& report)
{
    using json = nlohmann::ordered_json;
    const auto optional = [](const std::optional<double>& value) {
        return value ? json(*value) : json(nullptr);
    };
    json hoses = json::array();
    for (const HoseReport& hose : report.hoses) {
        json clearance = nullptr;
        if (hose.smallestClearance)
            clearance =
                json{{"distance", *hose.smallestClearance},
                     {"object", hose.clearanceObject},
                     {"axisPoint", hose.clearanceAxisPoint},
                     {"point", json::array({hose.clearancePoint.x(), hose.clearancePoint.y(),
                                            hose.clearancePoint.z()})},
                     {"motion", hose.clearanceMotion}};
        hoses.push_back(json{
            {"project", hose.project},
            {"id", hose.hoseId},
            {"name", hose.hoseName},
            {"material", hose.material},
            {"restLength", hose.restLength},
            {"fittingsAllowance", hose.fittingsAllowance},
            {"cutLength", hose.cutLength},
            {"shortestValidLength", optional(hose.shortestValidLength)},
            {"slack", optional(hose.slack)},
            {"fitNote", hose.fitNote},
            {"smallestBendRadius", optional(hose.smallestBendRadius)},
            {"minBendRadius", hose.minBendRadius > 0.0 ? json(hose.minBendRadius) : json(nullptr)},
            {"bendMargin", optional(hose.bendMargin)},
            {"smallestClearance", clearance},
            {"attachments", hose.attachments},
            {"clips", hose.clips}});
    }
    json materials = json::array();
    for (const MaterialTotal& total : report.materials)
        materials.push_back(json{{"material", total.material},
                                 {"hoses", total.hoses},
                                 {"restLength", total.restLength},
                                 {"fittingsAllowance", total.fittingsAllowance},
                                 {"cutLength", total.cutLength}});
    return json{{"projects", report.projects}, {"hoses", hoses}, {"materials", materials}}.dump(2) +
           "\n";
}

std::string markdownText(const LengthReport& report)
{
    std::ostringstream out;
    out << "| project | hose | name | material | cut length (m) | rest length (m) | fittings (m) | "
           "slack (m) | smallest bend radius (m) | bend margin (m) | smallest clearance (m) | "
           "nearest object | attachments | clips |\n"
        << "|---|---|---|---|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|\n";
    for (const HoseReport& hose : report.hoses) {
        std::string nearest;
        if (hose.smallestClearance)
            nearest = hose.clearanceObject + ", axis point " +
                      std::to_string(hose.clearanceAxisPoint) + ", " + hose.clearanceMotion;
        out << "| " << markdownCell(hose.project) << " | " << markdownCell(hose.hoseId) << " | "
            << markdownCell(hose.hoseName) << " | " << markdownCell(hose.material) << " | "
            << metres(hose.cutLength) << " | " << metres(hose.restLength) << " | "
            << metres(hose.fittingsAllowance) << " | "
            << (hose.slack ? metres(hose.slack) : markdownCell(hose.fitNote)) << " | "
            << metres(hose.smallestBendRadius) << " | " << metres(hose.bendMargin) << " | "
            << metres(hose.smallestClearance) << " | " << markdownCell(nearest) << " | "
            << hose.attachments << " | " << hose.clips << " |\n";
    }
    out << "\n| material | hoses | cut length (m) | rest length (m) | fittings (m) |\n"
        << "|---|---:|---:|---:|---:|\n";
    for (const MaterialTotal& total : report.materials)
        out << "| " << markdownCell(total.material) << " | " << total.hoses << " | "
            << metres(total.cutLength) << " | " << metres(total.restLength) << " | "
            << metres(total.fittingsAllowance) << " |\n";
    return out.str();
}

} // namespace

std::vector<MaterialTotal> materialTotals(const std::vector<HoseReport>& hoses)
{
    std::map<std::string, MaterialTotal> byName;
    for (const HoseReport& hose : hoses) {
        MaterialTotal& total = byName[hose.material];
        total.material = hose.material;
        ++total.hoses;
        total.restLength += hose.restLength;
        total.fittingsAllowance += hose.fittingsAllowance;
        total.cutLength += hose.cutLength;
    }
    std::vector<MaterialTotal> totals;
    for (auto& [name, total] : byName)
        totals.push_back(total);
    return totals;
}

LengthReport projectReport(const formats::Project& project, const fs::path& projectFile,
                           const formats::NamedRoots& roots, const ReportOptions& options)
{
    if (!(options.tolerance > 0.0) || !std::isfinite(options.tolerance))
        throw InvalidArgument("report tolerance: expected metres > 0, got " +
                              number(options.tolerance));
    // Progress: scene import to 10 %, the sweep to 40 %, the length fits the rest.
    const auto part = [&](double from, double to) -> std::function<bool(double)> {
        if (!options.progress) return {};
        return [&options, from, to](double fraction) {
            return options.progress(from + (to - from) * fraction);
        };
    };
    const formats::ImportedScenes scenes =
        formats::importProjectScenes(project, projectFile, roots, part(0.0, 0.1));

    SweepOptions sweepOptions;
    sweepOptions.steps = options.steps;
    sweepOptions.clearanceThreshold = options.clearanceThreshold;
    sweepOptions.reportDistance = options.reportDistance;
    sweepOptions.measurePoseWithoutMotions = true;
    sweepOptions.progress = part(0.1, options.fitLength ? 0.4 : 1.0);
    const SweepReport sweep = sweepMotions(project, scenes, sweepOptions);

    std::map<int, LengthFit> fits;
    if (options.fitLength) {
        LengthFitOptions fitOptions;
        fitOptions.steps = options.steps;
        fitOptions.clearanceThreshold = options.clearanceThreshold;
        fitOptions.reportDistance = options.reportDistance;
        fitOptions.tolerance = options.tolerance;
        fitOptions.progress = part(0.4, 1.0);
        bool anyFixed = false;
        for (const formats::HoseDefinition& hose : project.hoses)
            anyFixed = anyFixed || betweenFixedEnds(project, hose);
        if (anyFixed)
            for (LengthFit& fit : fitLengths(project, scenes, {}, fitOptions).hoses)
                fits[fit.hose] = std::move(fit);
    }

    LengthReport report;
    report.projects.push_back(projectFile.string());
    for (size_t h = 0; h < project.hoses.size(); ++h) {
        const formats::HoseDefinition& definition = project.hoses[h];
        HoseReport row;
        row.project = projectFile.string();
        row.hoseId = definition.id;
        row.hoseName = definition.name;
        row.material = materialName(definition);
        row.restLength = formats::hoseLength(project, definition);
        row.fittingsAllowance = definition.fittingsAllowance;
        row.cutLength = row.restLength + row.fittingsAllowance;
        row.attachments = static_cast<int>(definition.attachments.size());
        row.clips = static_cast<int>(definition.clips.size());
        if (const auto fit = fits.find(static_cast<int>(h)); fit != fits.end()) {
            if (fit->second.valid) {
                row.shortestValidLength = fit->second.shortest;
                row.slack = row.restLength - fit->second.shortest;
            } else {
                row.fitNote = "no valid length: " + fit->second.reason;
            }
        } else {
            row.fitNote = options.fitLength ? "not between fixed ends" : "not fitted";
        }
        if (h < sweep.hoses.size()) {
            const HoseSweep& swept = sweep.hoses[h];
            if (std::isfinite(swept.smallestBendRadius))
                row.smallestBendRadius = swept.smallestBendRadius;
            row.minBendRadius = swept.minBendRadius;
            if (row.smallestBendRadius && row.minBendRadius > 0.0)
                row.bendMargin = *row.smallestBendRadius - row.minBendRadius;
            // objects are nearest first.
            if (!swept.objects.empty() && std::isfinite(swept.objects.front().minDistance)) {
                const ObjectSweep& nearest = swept.objects.front();
                row.smallestClearance = nearest.minDistance;
                row.clearanceObject = nearest.sceneId + ":" + nearest.objectPath;
                row.clearanceAxisPoint = nearest.axisPoint;
                row.clearancePoint = nearest.onHose;
                row.clearanceMotion = motionAt(sweep, nearest.step);
            }
        }
        report.hoses.push_back(std::move(row));
    }
    report.materials = materialTotals(report.hoses);
    return report;
}

std::vector<fs::path> reportSources(const fs::path& projectOrFolder)
{
    std::error_code error;
    if (fs::is_directory(projectOrFolder, error)) {
        std::vector<fs::path> projects = findProjects(projectOrFolder.string());
        if (projects.empty())
            throw formats::FileError(projectOrFolder,
                                     "expected a folder with at least one *.ctproj, found none");
        return projects;
    }
    if (!fs::exists(projectOrFolder, error))
        throw formats::FileError(projectOrFolder,
                                 "expected a project file (*.ctproj) or a folder of them: no "
                                 "such file or folder");
    if (projectOrFolder.extension() != formats::kProjectExtension)
        throw formats::FileError(projectOrFolder,
                                 "expected a project file (*.ctproj) or a folder of them");
    return {projectOrFolder};
}

LengthReport reportProjects(const std::vector<fs::path>& projectFiles,
                            const formats::NamedRoots& roots, const ReportOptions& options)
{
    LengthReport report;
    for (const fs::path& file : projectFiles) {
        const formats::Project project = formats::loadProject(file, {roots});
        LengthReport one = projectReport(project, file, roots, options);
        report.projects.push_back(file.string());
        for (HoseReport& hose : one.hoses)
            report.hoses.push_back(std::move(hose));
    }
    report.materials = materialTotals(report.hoses);
    return report;
}

ReportFormat reportFormatFromName(const std::string& name)
{
    if (name == "csv") return ReportFormat::Csv;
    if (name == "json") return ReportFormat::Json;
    if (name == "md" || name == "markdown") return ReportFormat::Markdown;
    throw InvalidArgument("report format: expected csv, json or md, got \"" + name + "\"");
}

const char* extensionOf(ReportFormat format)
{
    switch (format) {
    case ReportFormat::Csv:
        return "csv";
    case ReportFormat::Json:
        return "json";
    case ReportFormat::Markdown:
        return "md";
    }
    return "csv";
}

std::string formatReport(const LengthReport& report, ReportFormat format)
{
    switch (format) {
    case ReportFormat::Csv:
        return csvText(report);
    case ReportFormat::Json:
        return jsonText(report);
    case ReportFormat::Markdown:
        return markdownText(report);
    }
    return csvText(report);
}

} // namespace chaintube::exporting
