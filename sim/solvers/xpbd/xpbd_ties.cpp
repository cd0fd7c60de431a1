// Ties of vertices onto points of other vertices or edges (xpbd_ties.hpp).
#include "sim/solvers/xpbd/xpbd_ties.hpp"

#include <algorithm>

namespace drape::sim::xpbd {

double tie_gap(const Tie& tie, const std::vector<Vec3>& x) {
  return (x[tie.a] - (1 - tie.t) * x[tie.b0] - tie.t * x[tie.b1]).norm();
}

double max_tie_gap(const std::vector<Tie>& ties, const std::vector<Vec3>& x) {
  double gap = 0;
  for (const Tie& tie : ties) gap = std::max(gap, tie_gap(tie, x));
  return gap;
}

void project_ties(const std::vector<Tie>& ties, std::vector<Vec3>& x, const double* w,
                  std::vector<int>* moved) {
  for (const Tie& tie : ties) {
    // grad C: +1 at a, -(1 - t) at b0, -t at b1 (times the identity); -1 at b0 when b1 is b0.
    const bool one = tie.b1 == tie.b0;
    const double ga = 1, g0 = one ? -1.0 : -(1 - tie.t), g1 = one ? 0.0 : -tie.t;
    const double wa = w[tie.a], w0 = w[tie.b0], w1 = one ? 0.0 : w[tie.b1];
    const double denom = wa * ga * ga + w0 * g0 * g0 + w1 * g1 * g1;
    if (denom <= 0) continue;
    const Vec3 c = x[tie.a] + g0 * x[tie.b0] + g1 * x[tie.b1];
    const Vec3 lambda = -c / denom;
    x[tie.a] += (wa * ga) * lambda;
    x[tie.b0] += (w0 * g0) * lambda;
    x[tie.b1] += (w1 * g1) * lambda;
    if (moved) {
      if (wa > 0) moved->push_back(tie.a);
      if (w0 > 0) moved->push_back(tie.b0);
      if (w1 > 0) moved->push_back(tie.b1);
    }
  }
}

}  // namespace drape::sim::xpbd
