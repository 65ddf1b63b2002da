// The bounded update (Hose::setBudget): the scope of one update entry point and a share of its
// budget for one attempt among several. Internal to lib/.
#pragma once

#include "chaintube/hose.h"

#include <algorithm>

namespace chaintube {

/// An update entry point (grab, moveAttachments, step, …). The outermost one takes the hose's
/// budget (or none, `bounded` false: sag, settle); nested ones share it. cut() says whether a
/// solver within this scope stopped for the budget.
class BudgetScope
{
public:
    explicit BudgetScope(Hose& hose, bool bounded = true)
        : m_hose(hose), m_outer(hose.m_updateDepth == 0), m_cutBefore(hose.m_budgetCut)
    {
        ++m_hose.m_updateDepth;
        if (m_outer)
            m_hose.m_budgetLeft =
                bounded && m_hose.m_budget.bounded() ? m_hose.m_budget.newtonSteps : -1;
        m_hose.m_budgetCut = false;
    }
    ~BudgetScope()
    {
        --m_hose.m_updateDepth;
        if (m_outer) {
            m_hose.m_budgetLeft = -1;
            m_hose.m_budgetCut = false;
        } else {
            m_hose.m_budgetCut = m_cutBefore || m_hose.m_budgetCut;
        }
    }
    BudgetScope(const BudgetScope&) = delete;
    BudgetScope& operator=(const BudgetScope&) = delete;
    bool cut() const { return m_hose.m_budgetCut; }
    bool bounded() const { return m_hose.m_budgetLeft >= 0; }
    bool exhausted() const { return m_hose.m_budgetLeft == 0; }

private:
    Hose& m_hose;
    bool m_outer;
    bool m_cutBefore;
};

/// At most `share` of the steps left for one attempt of several (the rest stays for the others);
/// no effect without a budget.
class BudgetShare
{
public:
    BudgetShare(Hose& hose, int share) : m_hose(hose), m_saved(hose.m_budgetLeft)
    {
        if (m_saved < 0) return;
        m_given = std::clamp(share, 0, m_saved);
        m_hose.m_budgetLeft = m_given;
    }
    ~BudgetShare()
    {
        if (m_saved >= 0) m_hose.m_budgetLeft = m_saved - (m_given - m_hose.m_budgetLeft);
    }
    BudgetShare(const BudgetShare&) = delete;
    BudgetShare& operator=(const BudgetShare&) = delete;

    /// Half of what is left, or all of it for the last of the attempts.
    static int half(const Hose& hose, bool last)
    {
        const int left = hose.m_budgetLeft;
        return left < 0 ? 0 : (last ? left : (left + 1) / 2);
    }

private:
    Hose& m_hose;
    int m_saved;
    int m_given = 0;
};

} // namespace chaintube
