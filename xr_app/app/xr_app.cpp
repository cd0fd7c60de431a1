// The drape OpenXR application's entry point (see xr_app.hpp) and the parts' shared report.
#include "xr_app/app/xr_app.hpp"

#include <malloc.h>

#include <cstdio>

#include "xr_app/app/xr_common.hpp"
#include "xr_app/app/xr_program.hpp"

namespace drape::app {

const char* to_string(XrAppState s) {
  switch (s) {
    case XrAppState::kNoRuntime:
      return "no_runtime";
    case XrAppState::kInstance:
      return "instance";
    case XrAppState::kSessionIdle:
      return "session_idle";
    case XrAppState::kSessionRunning:
      return "session_running";
    case XrAppState::kSessionStopping:
      return "session_stopping";
    case XrAppState::kSessionLost:
      return "session_lost";
    case XrAppState::kExiting:
      return "exiting";
    case XrAppState::kFailed:
      return "failed";
  }
  return "?";
}

void Report::note(const std::string& s) {
  r.log.push_back(s);
  if (verbose_) std::fprintf(stderr, "[drape xr] %s\n", s.c_str());
}

bool Report::ok(XrResult x, const char* what) {
  if (XR_SUCCEEDED(x)) return true;
  char buf[XR_MAX_RESULT_STRING_SIZE] = "";
  if (instance != XR_NULL_HANDLE) xrResultToString(instance, x, buf);
  r.error = std::string(what) + " failed: " + (buf[0] ? buf : std::to_string(x));
  note(r.error);
  return false;
}

XrPath xr_path(XrInstance instance, const char* s) {
  XrPath p = XR_NULL_PATH;
  xrStringToPath(instance, s, &p);
  return p;
}

XrAppResult run_xr_app(const XrAppOptions& opt) {
  XrAppResult res;
#ifdef M_TRIM_THRESHOLD
  if (opt.tune_malloc) {
    // lavapipe (llvmpipe's draw module) mallocs and frees tens of MB of vertex data per draw on
    // its queue thread; glibc returns the freed top of that thread's arena to the kernel
    // (madvise) every time and the next frame faults every page back in: 660k page faults and
    // ~30 ms of system time per frame at 2 x 512^2 (docs/xr.md, "Profile"). Keep freed memory in
    // the process instead (as GLIBC_TUNABLES=glibc.malloc.trim_threshold=... would).
    mallopt(M_TRIM_THRESHOLD, 512 << 20);
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
  }
#endif
  {
    XrProgram program(opt, &res);
    program.run();
    res.final_state = program.state();
  }
  if (res.final_state == XrAppState::kExiting && res.error.empty())
    res.exit_code = 0;
  else if (res.final_state == XrAppState::kNoRuntime)
    res.exit_code = 3;
  else
    res.exit_code = 1;
  return res;
}

}  // namespace drape::app
