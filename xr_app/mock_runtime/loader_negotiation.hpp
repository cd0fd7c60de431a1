// The loader <-> runtime negotiation structures of the OpenXR loader specification
// ("OpenXR Loader - Design and Operation", section "Runtime Interface Negotiation").
// Debian's libopenxr-dev does not ship loader_interfaces.h, so the layouts are declared here
// from the specification text (interface version 1).
#pragma once

#include <openxr/openxr.h>

#include <cstddef>
#include <cstdint>

namespace drape::mock {

enum XrLoaderInterfaceStructs : int32_t {
  kLoaderInterfaceStructUninitialized = 0,
  kLoaderInterfaceStructLoaderInfo = 1,
  kLoaderInterfaceStructApiLayerRequest = 2,
  kLoaderInterfaceStructRuntimeRequest = 3,
  kLoaderInterfaceStructApiLayerCreateInfo = 4,
  kLoaderInterfaceStructApiLayerNextInfo = 5,
};

constexpr uint32_t kLoaderInfoStructVersion = 1;
constexpr uint32_t kRuntimeInfoStructVersion = 1;
constexpr uint32_t kCurrentLoaderRuntimeVersion = 1;

// Filled by the loader, read by the runtime.
struct XrNegotiateLoaderInfo {
  XrLoaderInterfaceStructs structType;  // kLoaderInterfaceStructLoaderInfo
  uint32_t structVersion;               // kLoaderInfoStructVersion
  size_t structSize;                    // sizeof(XrNegotiateLoaderInfo)
  uint32_t minInterfaceVersion;
  uint32_t maxInterfaceVersion;
  XrVersion minApiVersion;
  XrVersion maxApiVersion;
};

// Filled by the runtime.
struct XrNegotiateRuntimeRequest {
  XrLoaderInterfaceStructs structType;  // kLoaderInterfaceStructRuntimeRequest
  uint32_t structVersion;               // kRuntimeInfoStructVersion
  size_t structSize;                    // sizeof(XrNegotiateRuntimeRequest)
  uint32_t runtimeInterfaceVersion;
  XrVersion runtimeApiVersion;
  PFN_xrGetInstanceProcAddr getInstanceProcAddr;
};

}  // namespace drape::mock
