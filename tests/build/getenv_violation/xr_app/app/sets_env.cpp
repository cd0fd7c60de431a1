// Fixture of build_no_getenv_rejects_environment: a library source that sets the environment.
#include <cstdlib>

void choose() {
  setenv("SOME_RUNTIME", "x", 1);
}
