// What the parts of the OpenXR app share: the OpenXR headers with the Vulkan bindings, the run's
// report (result, log, error) and small OpenXR helpers.
#pragma once

#include <vulkan/vulkan.h>
// (Vulkan first: openxr_platform.h uses its types)
#define XR_USE_GRAPHICS_API_VULKAN
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

#include <string>

#include "xr_app/app/xr_app.hpp"

namespace drape::app {

// The run's result and log: every part records its errors and notable events here.
class Report {
 public:
  Report(XrAppResult& result, bool verbose) : r(result), verbose_(verbose) {}
  XrAppResult& r;
  XrInstance instance = XR_NULL_HANDLE;  // names results (xrResultToString) once created

  // Appends to the log (and stderr when verbose).
  void note(const std::string& s);
  // True when x succeeded; else records "<what> failed: <result>" as the error.
  bool ok(XrResult x, const char* what);

 private:
  bool verbose_;
};

// An instance-level function (an extension's): nullptr when the runtime does not offer it.
template <class F>
F xr_function(XrInstance instance, const char* name) {
  PFN_xrVoidFunction f = nullptr;
  if (XR_FAILED(xrGetInstanceProcAddr(instance, name, &f))) return nullptr;
  return reinterpret_cast<F>(f);
}

XrPath xr_path(XrInstance instance, const char* s);

}  // namespace drape::app
