// Fixture of build_no_getenv_rejects_environment: an executable's command may read it too.
#include <cstdlib>

const char* home() {
  return std::getenv("HOME");
}
