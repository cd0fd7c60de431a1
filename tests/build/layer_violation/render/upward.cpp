// A renderer source that includes the solvers: the layer check must reject it.
#include "sim/solvers/solver.hpp"
