// ChainTube editor — the Import Scene dialog: after a scene file was read, what the reader
// assumed about it (its length unit and up axis, and where each came from) and where the scene
// goes, each changeable before the scene is added to the project.
#pragma once

#include "chaintube/formats/scene.h"

#include <QDialog>
#include <optional>

class QComboBox;
class QLabel;
class QRadioButton;

namespace chaintube::editor {

class ImportDialog : public QDialog
{
    Q_OBJECT
public:
    /// Where the imported scene goes.
    enum class Placement {
        AsInFile,       ///< where the file's coordinates put it
        AtOrigin,       ///< its bounding box centred on the origin in X and Z, standing on Y = 0
        BesideExisting, ///< next to what the project holds already, along +X, on the same floor
    };

    /// `scene` as read with the detected units (its bounds are shown, converted to the chosen
    /// unit and axis); `haveContent` chooses the default placement (beside what is there, or
    /// at the origin in an empty project).
    ImportDialog(const formats::ImportedScene& scene, bool haveContent, QWidget* parent = nullptr);

    /// Metres per source unit the author chose; nullopt: as the reader detected.
    std::optional<double> metresPerUnit() const;
    /// Up axis the author chose; nullopt: as the reader detected.
    std::optional<formats::UpAxis> upAxis() const;
    Placement placement() const;

private:
    void updateSize();

    const formats::SourceUnits m_detected;
    Eigen::Vector3d m_detectedSize; ///< bounding box extents (metres) with the detected units
    QComboBox* m_unit;
    QComboBox* m_upAxis;
    QLabel* m_size;
    QRadioButton* m_asInFile;
    QRadioButton* m_atOrigin;
    QRadioButton* m_beside;
};

/// World bounding box (metres) of every mesh of a scene at its file transforms: {low, high};
/// low > high in every coordinate when it has no vertex.
std::pair<Vec3, Vec3> sceneBounds(const formats::ImportedScene& scene);

} // namespace chaintube::editor
