// STEP (AP203/AP214) import through OpenCASCADE XCAF: product structure → nodes, parts →
// tessellated meshes.
#include "import_internal.h"

#include <BRepMesh_IncrementalMesh.hxx>
#include <BRep_Tool.hxx>
#include <Interface_Static.hxx>
#include <Message_ProgressIndicator.hxx>
#include <Message_ProgressScope.hxx>
#include <Poly_Triangulation.hxx>
#include <STEPCAFControl_Reader.hxx>
#include <STEPControl_Reader.hxx>
#include <Standard_Failure.hxx>
#include <TColStd_SequenceOfAsciiString.hxx>
#include <TDF_Label.hxx>
#include <TDF_LabelSequence.hxx>
#include <TDF_Tool.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <TopExp_Explorer.hxx>
#include <TopLoc_Location.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <cctype>
#include <cmath>
#include <gp_Trsf.hxx>
#include <map>

namespace chaintube::formats::detail {

namespace {

/// OCCT calls UserBreak() from its algorithms; Show() whenever the position advances.
class OcctProgress : public Message_ProgressIndicator
{
public:
    OcctProgress(ProgressStage& stage, double begin, double end)
        : m_stage(stage), m_begin(begin), m_end(end)
    {
    }
    Standard_Boolean UserBreak() override { return m_stage.cancelRequested(); }
    void Show(const Message_ProgressScope&, const Standard_Boolean) override
    {
        m_stage.reportNoThrow(m_begin + (m_end - m_begin) * GetPosition());
    }

private:
    ProgressStage& m_stage;
    double m_begin;
    double m_end;
};

std::string labelName(const TDF_Label& label)
{
    Handle(TDataStd_Name) name;
    if (!label.FindAttribute(TDataStd_Name::GetID(), name)) return {};
    const TCollection_ExtendedString& extended = name->Get();
    // TCollection_AsciiString converts to UTF-8 when given an extended string.
    return TCollection_AsciiString(extended, '?').ToCString();
}

Mat4 toMat4(const gp_Trsf& transform)
{
    Mat4 m = Mat4::Identity();
    for (int row = 1; row <= 3; ++row)
        for (int column = 1; column <= 4; ++column)
            m(row - 1, column - 1) = transform.Value(row, column);
    return m;
}

/// Metres per unit for the unit names OCCT reports from a file's SI_UNIT / CONVERSION_BASED_UNIT.
double metresForUnitName(std::string name)
{
    for (char& c : name)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    static const std::map<std::string, double> known = {
        {"mm", 0.001},    {"millimetre", 0.001}, {"millimeter", 0.001},
        {"cm", 0.01},     {"centimetre", 0.01},  {"centimeter", 0.01},
        {"m", 1.0},       {"metre", 1.0},        {"meter", 1.0},
        {"km", 1000.0},   {"inch", 0.0254},      {"in", 0.0254},
        {"ft", 0.3048},   {"foot", 0.3048},      {"mile", 1609.344},
        {"micron", 1e-6}, {"um", 1e-6}};
    const auto found = known.find(name);
    return found == known.end() ? 0.0 : found->second;
}

class StepSceneBuilder
{
public:
    StepSceneBuilder(ImportedScene& scene, Handle(XCAFDoc_ShapeTool) shapes,
                     double linearDeflection, double angularDeflection, ProgressStage& progress,
                     int partCount)
        : m_scene(scene), m_shapes(shapes), m_linearDeflection(linearDeflection),
          m_angularDeflection(angularDeflection), m_progress(progress), m_partCount(partCount)
    {
    }

    /// Adds the node for `label` (a free shape or a component instance) under parent.
    void addNode(const TDF_Label& label, int parent, int depth)
    {
        if (depth > 256) throw FileError(m_scene.file, "assembly nesting deeper than 256 levels");
        TDF_Label definition = label;
        Mat4 local = Mat4::Identity();
        if (XCAFDoc_ShapeTool::IsReference(label)) {
            XCAFDoc_ShapeTool::GetReferredShape(label, definition);
            local = toMat4(XCAFDoc_ShapeTool::GetLocation(label).Transformation());
        }
        SceneNode node;
        // An instance's own name ("nut_1") identifies it among its siblings; fall back to the
        // product's name ("nut").
        node.name = labelName(label);
        if (node.name.empty()) node.name = labelName(definition);
        node.parent = parent;
        node.localTransform = local;
        const int index = static_cast<int>(m_scene.nodes.size());
        m_scene.nodes.push_back(node);
        if (parent >= 0) m_scene.nodes[static_cast<size_t>(parent)].children.push_back(index);

        if (XCAFDoc_ShapeTool::IsAssembly(definition)) {
            TDF_LabelSequence components;
            XCAFDoc_ShapeTool::GetComponents(definition, components, Standard_False);
            for (Standard_Integer i = 1; i <= components.Length(); ++i)
                addNode(components.Value(i), index, depth + 1);
        } else {
            const int mesh = meshFor(definition);
            if (mesh >= 0) m_scene.nodes[static_cast<size_t>(index)].meshes.push_back(mesh);
        }
    }

private:
    /// Tessellates a part once; instances share the mesh. −1 if it has no faces.
    int meshFor(const TDF_Label& part)
    {
        TCollection_AsciiString entry;
        TDF_Tool::Entry(part, entry);
        const std::string key = entry.ToCString();
        const auto cached = m_meshOfPart.find(key);
        if (cached != m_meshOfPart.end()) return cached->second;
        m_progress.report(0.6 + 0.4 * static_cast<double>(m_meshOfPart.size()) /
                                    std::max(1, m_partCount));

        const TopoDS_Shape shape = XCAFDoc_ShapeTool::GetShape(part);
        BRepMesh_IncrementalMesh mesher(shape, m_linearDeflection, Standard_False,
                                        m_angularDeflection, Standard_False);
        SceneMesh mesh;
        mesh.name = labelName(part);
        for (TopExp_Explorer faces(shape, TopAbs_FACE); faces.More(); faces.Next()) {
            const TopoDS_Face& face = TopoDS::Face(faces.Current());
            TopLoc_Location location;
            const Handle(Poly_Triangulation) triangulation =
                BRep_Tool::Triangulation(face, location);
            if (triangulation.IsNull()) continue;
            const gp_Trsf transform = location.Transformation();
            const bool reversed = face.Orientation() == TopAbs_REVERSED;
            const auto base = static_cast<std::uint32_t>(mesh.vertexCount());
            const Standard_Integer nodeCount = triangulation->NbNodes();
            std::vector<Eigen::Vector3d> normals(static_cast<size_t>(nodeCount),
                                                 Eigen::Vector3d::Zero());
            std::vector<Eigen::Vector3d> points(static_cast<size_t>(nodeCount));
            for (Standard_Integer i = 1; i <= nodeCount; ++i) {
                const gp_Pnt p = triangulation->Node(i).Transformed(transform);
                points[static_cast<size_t>(i - 1)] = {p.X(), p.Y(), p.Z()};
            }
            for (Standard_Integer t = 1; t <= triangulation->NbTriangles(); ++t) {
                Standard_Integer a = 0, b = 0, c = 0;
                triangulation->Triangle(t).Get(a, b, c);
                if (reversed) std::swap(b, c);
                const Eigen::Vector3d& pa = points[static_cast<size_t>(a - 1)];
                const Eigen::Vector3d area = (points[static_cast<size_t>(b - 1)] - pa)
                                                 .cross(points[static_cast<size_t>(c - 1)] - pa);
                for (Standard_Integer v : {a, b, c})
                    normals[static_cast<size_t>(v - 1)] += area;
                for (Standard_Integer v : {a, b, c})
                    mesh.indices.push_back(base + static_cast<std::uint32_t>(v - 1));
            }
            for (size_t i = 0; i < points.size(); ++i) {
                Eigen::Vector3d n = normals[i];
                n = n.norm() > 0 ? n.normalized() : Eigen::Vector3d(0, 1, 0);
                for (int k = 0; k < 3; ++k) {
                    mesh.positions.push_back(static_cast<float>(points[i](k)));
                    mesh.normals.push_back(static_cast<float>(n(k)));
                }
            }
        }
        int index = -1;
        if (!mesh.indices.empty()) {
            index = static_cast<int>(m_scene.meshes.size());
            m_scene.meshes.push_back(std::move(mesh));
        }
        m_meshOfPart[key] = index;
        return index;
    }

    ImportedScene& m_scene;
    Handle(XCAFDoc_ShapeTool) m_shapes;
    double m_linearDeflection;
    double m_angularDeflection;
    ProgressStage& m_progress;
    int m_partCount;
    std::map<std::string, int> m_meshOfPart; ///< label entry ("0:1:1:3") → mesh
};

} // namespace

ReaderResult importStep(const std::filesystem::path& file, const ImportOptions& options,
                        ProgressStage& progress)
{
    ReaderResult result;
    ImportedScene& scene = result.scene;
    scene.file = file;
    scene.format = "STEP";
    try {
        // Let OCCT convert the file's length unit to metres for us.
        Interface_Static::SetCVal("xstep.cascade.unit", "M");

        Handle(XCAFApp_Application) application = XCAFApp_Application::GetApplication();
        Handle(TDocStd_Document) document;
        application->NewDocument("MDTV-XCAF", document);
        XCAFDoc_DocumentTool::SetLengthUnit(document, 1.0); // document unit: metre

        STEPCAFControl_Reader reader;
        reader.SetNameMode(Standard_True);
        reader.SetColorMode(Standard_False);
        reader.SetLayerMode(Standard_False);
        const IFSelect_ReturnStatus status = reader.ReadFile(file.string().c_str());
        if (status != IFSelect_RetDone)
            throw FileError(file, "not a readable STEP file (OpenCASCADE could not parse it; "
                                  "truncated or not ISO 10303-21?)");
        progress.report(0.2);

        // The file's stated length unit (for the report and for a user's override).
        TColStd_SequenceOfAsciiString lengthUnits, angleUnits, solidAngleUnits;
        reader.ChangeReader().FileUnits(lengthUnits, angleUnits, solidAngleUnits);
        double fileUnitMetres = 0.0;
        std::string fileUnitName;
        if (lengthUnits.Length() > 0) {
            fileUnitName = lengthUnits.Value(1).ToCString();
            fileUnitMetres = metresForUnitName(fileUnitName);
        }

        Handle(OcctProgress) indicator = new OcctProgress(progress, 0.2, 0.6);
        const bool transferred = reader.Transfer(document, indicator->Start());
        progress.throwIfCancelRequested();
        if (!transferred) throw FileError(file, "the STEP file has no transferable shapes");

        double documentUnitMetres = 1.0;
        if (!XCAFDoc_DocumentTool::GetLengthUnit(document, documentUnitMetres) ||
            !(documentUnitMetres > 0.0))
            documentUnitMetres = 1.0;

        Handle(XCAFDoc_ShapeTool) shapes = XCAFDoc_DocumentTool::ShapeTool(document->Main());
        TDF_LabelSequence freeShapes;
        shapes->GetFreeShapes(freeShapes);
        if (freeShapes.IsEmpty()) throw FileError(file, "the STEP file contains no shapes");
        TDF_LabelSequence allShapes;
        shapes->GetShapes(allShapes);

        // Tolerance is given in metres; the document is in documentUnitMetres.
        StepSceneBuilder builder(scene, shapes, options.chordalTolerance / documentUnitMetres,
                                 options.angularTolerance, progress, allShapes.Length());
        if (freeShapes.Length() == 1) {
            builder.addNode(freeShapes.Value(1), -1, 0);
        } else {
            SceneNode root;
            root.name = file.stem().string();
            scene.nodes.push_back(root);
            for (Standard_Integer i = 1; i <= freeShapes.Length(); ++i)
                builder.addNode(freeShapes.Value(i), 0, 1);
        }
        application->Close(document);

        result.metresPerReaderUnit = documentUnitMetres;
        SourceUnits& units = scene.sourceUnits;
        units.upAxis = UpAxis::PositiveZ; // CAD convention; STEP itself has no up axis
        units.upAxisSource = UnitSource::Assumed;
        if (fileUnitMetres > 0.0) {
            units.metresPerUnit = fileUnitMetres;
            units.unitName = fileUnitName;
            units.unitSource = UnitSource::FileHeader;
            result.sourceUnitsPerReaderUnit = documentUnitMetres / fileUnitMetres;
        } else {
            units.metresPerUnit = 0.001;
            units.unitName = fileUnitName.empty() ? "millimetre" : fileUnitName;
            units.unitSource = UnitSource::Assumed;
            result.sourceUnitsPerReaderUnit = documentUnitMetres / 0.001;
        }
    } catch (const Standard_Failure& failure) {
        throw FileError(file, std::string("OpenCASCADE failed reading the STEP file: ") +
                                  failure.GetMessageString());
    }
    progress.report(1.0);
    return result;
}

} // namespace chaintube::formats::detail
