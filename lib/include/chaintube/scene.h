// ChainTube — many hoses updated per frame.
#pragma once

#include "chaintube/hose.h"
#include "chaintube/surface.h"

#include <memory>
#include <vector>

namespace chaintube {

/// A set of hoses with their surfaces. A hose whose revision did not change since the last
/// updateSurfaces() is not recomputed.
class Scene
{
public:
    /// Adds a hose and returns its index.
    int addHose(Hose hose);
    int hoseCount() const { return static_cast<int>(m_hoses.size()); }
    Hose& hose(int index) { return m_hoses.at(static_cast<size_t>(index)); }
    const Hose& hose(int index) const { return m_hoses.at(static_cast<size_t>(index)); }
    const HoseSurface& surface(int index) const
    {
        return m_surfaces.at(static_cast<size_t>(index));
    }

    struct FrameStats
    {
        int recomputed = 0;
        int skipped = 0;
    };
    /// Bring every hose's surface up to date.
    FrameStats updateSurfaces();
    /// One gravity step (Hose::step) of every hose with HoseSpec::gravity on; hoses with
    /// gravity off or settled cost one comparison. Returns how many hoses moved.
    int step();

private:
    std::vector<Hose> m_hoses;
    std::vector<HoseSurface> m_surfaces;
};

} // namespace chaintube
