// Fixture of build_no_getenv_rejects_environment: the mock runtime may read its environment.
#include <cstdlib>

const char* scenario() {
  return std::getenv("DRAPE_MOCK_SCENARIO");
}
