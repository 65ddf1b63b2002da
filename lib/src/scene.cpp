#include "chaintube/scene.h"

namespace chaintube {

int Scene::addHose(Hose hose)
{
    m_surfaces.emplace_back(hose);
    m_hoses.push_back(std::move(hose));
    return static_cast<int>(m_hoses.size()) - 1;
}

Scene::FrameStats Scene::updateSurfaces()
{
    FrameStats stats;
    for (size_t i = 0; i < m_hoses.size(); ++i) {
        if (m_surfaces[i].update(m_hoses[i]))
            ++stats.recomputed;
        else
            ++stats.skipped;
    }
    return stats;
}

int Scene::step()
{
    int moved = 0;
    for (Hose& hose : m_hoses)
        moved += hose.step().movedPoints > 0 ? 1 : 0;
    return moved;
}

} // namespace chaintube
