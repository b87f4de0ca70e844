/* The speed-against-error front (eval.h): O(n^2), n is a few hundred settings at most. */
#include "render/eval/eval.h"

#include <math.h>

/* a dominates b: no worse in both, better in one. */
static bool dominates(double ca, double ea, double cb, double eb)
{
    return ca <= cb && ea <= eb && (ca < cb || ea < eb);
}

int lr_eval_pareto(const double *cost, const double *error, int n, bool *on_front)
{
    int count = 0;
    for (int i = 0; i < n; i++) {
        bool ok = isfinite(cost[i]) && isfinite(error[i]);
        for (int j = 0; ok && j < n; j++) {
            if (j == i || !isfinite(cost[j]) || !isfinite(error[j]))
                continue;
            if (dominates(cost[j], error[j], cost[i], error[i]) ||
                (j < i && cost[j] == cost[i] && error[j] == error[i]))
                ok = false;
        }
        on_front[i] = ok;
        count += ok;
    }
    return count;
}
