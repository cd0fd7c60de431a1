// Fixture of build_no_getenv_rejects_environment: a library source that reads the environment.
#include <cstdlib>

bool verbose() {
  return std::getenv("SOME_FLAG") != nullptr;
}
