// A core header that includes an operation: the layer check must reject it.
#pragma once
#include "sim/ops/cut.hpp"
