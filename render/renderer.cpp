// Vulkan side of the renderer (render/renderer.hpp). Resources are managed simply: every buffer
// is host-visible, coherent and persistently mapped (one allocation each, grown by doubling);
// images are device-local with one allocation each; a frame is recorded into one command buffer
// and the call waits on one fence, so nothing is in flight when it returns.
#include "render/renderer.hpp"

#include <time.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <map>
#include <tuple>

#include "scene_frag.spv.h"
#include "scene_vert.spv.h"
#include "sim/form/dress_form.hpp"
#include "text_frag.spv.h"
#include "text_vert.spv.h"

namespace drape::render {
namespace {

struct PushConstants {
  float view_proj[16];
  float eye[4];
  float heights[4];
  float angles[4];
  int32_t flags[4];
};
static_assert(sizeof(PushConstants) == 128, "push constants must fit the guaranteed 128 bytes");

struct TextPushConstants {  // render/shaders/text.vert
  float mvp[16];
  int32_t flags[4];
};

struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* mapped = nullptr;
  VkDeviceSize size = 0;
};

struct Attachment {
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
};

struct TargetKey {
  VkImage image;
  uint32_t layer, width, height;
  VkFormat format;
  int samples;
  VkImageLayout final_layout;
  VkImage depth_image;
  VkFormat depth_format;
  auto tie() const {
    return std::tie(image, layer, width, height, format, samples, final_layout, depth_image,
                    depth_format);
  }
  bool operator<(const TargetKey& o) const { return tie() < o.tie(); }
};

struct TargetFb {
  VkImageView view = VK_NULL_HANDLE;
  VkImageView depth_view = VK_NULL_HANDLE;             // of the caller's depth image
  VkFramebuffer overlay_framebuffer = VK_NULL_HANDLE;  // colour + the renderer's depth
  VkFramebuffer framebuffer = VK_NULL_HANDLE;
};

// Formats holding linear values with more than 8 bits need no encoding either.
bool needs_shader_encode(VkFormat f) {
  switch (f) {
    case VK_FORMAT_R8G8B8A8_UNORM:
    case VK_FORMAT_B8G8R8A8_UNORM:
    case VK_FORMAT_A8B8G8R8_UNORM_PACK32:
    case VK_FORMAT_A2B10G10R10_UNORM_PACK32:
    case VK_FORMAT_A2R10G10B10_UNORM_PACK32:
      return true;
    default:
      return false;
  }
}

float srgb_encode(float c) {
  c = std::clamp(c, 0.0f, 1.0f);
  return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

PushConstants push_constants(const sim::SceneSnapshot& snap, const View& view, VkFormat format,
                             const DrawOptions& opt) {
  PushConstants pc{};
  const Mat4f vp = view.view_proj();
  std::memcpy(pc.view_proj, vp.data(), sizeof(pc.view_proj));
  pc.eye[0] = view.eye.x();
  pc.eye[1] = view.eye.y();
  pc.eye[2] = view.eye.z();
  pc.eye[3] = opt.grain_spacing;
  if (snap.form) {
    const auto& lm = snap.form->landmarks();
    pc.heights[0] = static_cast<float>(lm.waist_y);
    pc.heights[1] = static_cast<float>(lm.hip_y);
    pc.heights[2] = static_cast<float>(lm.bust_y);
    pc.angles[0] = static_cast<float>(lm.centre_front_theta);
    pc.angles[1] = static_cast<float>(lm.centre_back_theta);
    pc.angles[2] = static_cast<float>(lm.left_side_theta);
    pc.angles[3] = static_cast<float>(lm.right_side_theta);
  }
  pc.heights[3] = opt.line_half_width;
  pc.flags[0] = static_cast<int32_t>(opt.colour_map);
  pc.flags[1] = needs_shader_encode(format) ? 1 : 0;
  pc.flags[2] = opt.grain ? 1 : 0;
  return pc;
}

// Colour (the background, encoded when the shader encodes), depth, resolve colour.
std::array<VkClearValue, 3> clear_values(const DrawOptions& opt, bool encode) {
  std::array<VkClearValue, 3> clears{};
  for (int k = 0; k < 3; ++k)
    clears[0].color.float32[k] = encode ? srgb_encode(opt.background[k]) : opt.background[k];
  clears[0].color.float32[3] = 1.0f;
  clears[1].depthStencil = {1.0f, 0};
  clears[2] = clears[0];
  return clears;
}

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

}  // namespace

struct Renderer::Impl {
  std::unique_ptr<VulkanContext> ctx;
  int samples = 1;
  bool lost = false;
  FrameStats stats;

  VkCommandPool pool = VK_NULL_HANDLE;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  VkShaderModule vs = VK_NULL_HANDLE, fs = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  // With a caller's depth image a view is drawn in two passes: kScene (cloth, form, floor into
  // the colour and the caller's depth, stored), then the depth is copied into the renderer's
  // own and kOverlay (hands and markers, the colour and that copy loaded) draws over it.
  enum PassKind { kWhole = 0, kScene = 1, kOverlay = 2 };
  // (colour format, samples, final layout, depth format, kind)
  std::map<std::tuple<VkFormat, int, VkImageLayout, VkFormat, int>, VkRenderPass> passes;
  std::map<std::tuple<VkFormat, int, uint32_t, VkFormat>, VkPipeline>
      pipelines;  // + modes mask, depth format
  std::map<std::tuple<uint32_t, uint32_t, VkFormat, int, VkFormat>,
           std::pair<Attachment, Attachment>>
      attachments;  // (depth, msaa colour) per size/format/samples/depth format
  std::map<TargetKey, TargetFb> targets;

  // Offscreen target + readback.
  Attachment offscreen;
  uint32_t off_w = 0, off_h = 0;
  Buffer readback;

  // Geometry: the static part (form, floor) is rebuilt only when the form or options change.
  Buffer static_vb, static_ib, cloth_vb, cloth_ib, dyn_vb, dyn_ib;
  uint32_t static_count = 0;
  uint32_t static_split = 0;  // indices [0, split): the form; [split, count): the floor
  uint32_t static_modes[2] = {0, 0}, cloth_modes = 0;
  const sim::DressForm* cached_form = nullptr;
  std::shared_ptr<const sim::DressForm> form_ref;  // keeps the cached form alive
  bool cached_floor = false;
  float cached_spacing = -1;
  int cached_angle_step = -1;
  std::array<float, 3> cached_colour{-1, -1, -1};
  Mesh mesh;
  // The cloth's vertices are kept while the snapshot's cloth and the options colouring it are
  // unchanged (a free-running sim publishes slower than the frames are drawn).
  struct ClothInputs {
    std::vector<sim::Vec3f> positions, normals;
    std::vector<sim::Vec2f> material;
    std::vector<uint32_t> indices;
    std::vector<float> strain;
    const sim::DressForm* form = nullptr;
    ColourMap colour_map = ColourMap::kNone;
    float strain_range = 0, ease_range = 0;
    std::array<float, 3> colour{};
  } cloth_in;
  bool cloth_valid = false;
  uint32_t cloth_count = 0;

  // The feedback panel (TextPanel): its pipeline (text.vert/frag, alpha-blended, no depth test
  // or write), the glyph atlas (R8, uploaded once from `staging` in the first frame's command
  // buffer), its sampler and descriptor, and the panel's quads (rebuilt when the version changes).
  struct TextGpu {
    std::string font_path, error;
    bool font_tried = false, atlas_uploaded = false;
    FontAtlas font;
    Attachment atlas;
    Buffer staging, vb, ib;
    VkSampler sampler = VK_NULL_HANDLE;
    VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
    VkDescriptorPool pool = VK_NULL_HANDLE;
    VkDescriptorSet set = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkShaderModule vs = VK_NULL_HANDLE, fs = VK_NULL_HANDLE;
    std::map<std::tuple<VkFormat, int, VkFormat>, VkPipeline> pipelines;
    TextPanel panel;
    uint64_t built_version = 0;
    bool built = false;
    uint32_t count = 0;
    float height = 0;
  } text;

  ~Impl() { destroy(); }

  VkDevice dev() const { return ctx->device; }

  Status fail(const std::string& what, VkResult r) {
    if (r == VK_ERROR_DEVICE_LOST) lost = true;
    return Status{"vulkan: " + what + " failed: " + vk_result_name(r) +
                  (r == VK_ERROR_DEVICE_LOST ? " (device lost: recreate the renderer)" : "")};
  }

  sim::Result<uint32_t> memory_type(uint32_t bits, VkMemoryPropertyFlags want) const {
    for (uint32_t i = 0; i < ctx->memory.memoryTypeCount; ++i)
      if ((bits & (1u << i)) && (ctx->memory.memoryTypes[i].propertyFlags & want) == want) return i;
    return sim::Error{"vulkan: no memory type with the required properties"};
  }

  void destroy_buffer(Buffer& b) {
    if (b.buffer) vkDestroyBuffer(dev(), b.buffer, nullptr);
    if (b.memory) vkFreeMemory(dev(), b.memory, nullptr);
    b = Buffer{};
  }
  void destroy_attachment(Attachment& a) {
    if (a.view) vkDestroyImageView(dev(), a.view, nullptr);
    if (a.image) vkDestroyImage(dev(), a.image, nullptr);
    if (a.memory) vkFreeMemory(dev(), a.memory, nullptr);
    a = Attachment{};
  }

  Status ensure_buffer(Buffer& b, VkDeviceSize size, VkBufferUsageFlags usage) {
    if (b.size >= size && b.buffer) return {};
    destroy_buffer(b);
    VkDeviceSize cap = 4096;
    while (cap < size) cap *= 2;
    VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bi.size = cap;
    bi.usage = usage;
    bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    if (VkResult r = vkCreateBuffer(dev(), &bi, nullptr, &b.buffer); r != VK_SUCCESS)
      return fail("vkCreateBuffer", r);
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(dev(), b.buffer, &req);
    auto type = memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                                    VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    if (!type) return Status{type.error()};
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = *type;
    if (VkResult r = vkAllocateMemory(dev(), &ai, nullptr, &b.memory); r != VK_SUCCESS)
      return fail("vkAllocateMemory", r);
    vkBindBufferMemory(dev(), b.buffer, b.memory, 0);
    if (VkResult r = vkMapMemory(dev(), b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped); r != VK_SUCCESS)
      return fail("vkMapMemory", r);
    b.size = cap;
    return {};
  }

  Status make_image(Attachment& a, uint32_t w, uint32_t h, VkFormat fmt, VkImageUsageFlags usage,
                    VkImageAspectFlags aspect, int nsamples) {
    VkImageCreateInfo ii{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ii.imageType = VK_IMAGE_TYPE_2D;
    ii.format = fmt;
    ii.extent = {w, h, 1};
    ii.mipLevels = 1;
    ii.arrayLayers = 1;
    ii.samples = static_cast<VkSampleCountFlagBits>(nsamples);
    ii.tiling = VK_IMAGE_TILING_OPTIMAL;
    ii.usage = usage;
    ii.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    if (VkResult r = vkCreateImage(dev(), &ii, nullptr, &a.image); r != VK_SUCCESS)
      return fail("vkCreateImage", r);
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(dev(), a.image, &req);
    auto type = memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    if (!type) type = memory_type(req.memoryTypeBits, 0);
    if (!type) return Status{type.error()};
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = *type;
    if (VkResult r = vkAllocateMemory(dev(), &ai, nullptr, &a.memory); r != VK_SUCCESS)
      return fail("vkAllocateMemory", r);
    vkBindImageMemory(dev(), a.image, a.memory, 0);
    VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vi.image = a.image;
    vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vi.format = fmt;
    vi.subresourceRange = {aspect, 0, 1, 0, 1};
    if (VkResult r = vkCreateImageView(dev(), &vi, nullptr, &a.view); r != VK_SUCCESS)
      return fail("vkCreateImageView", r);
    return {};
  }

  Status init(int want_samples) {
    VkCommandPoolCreateInfo pi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pi.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pi.queueFamilyIndex = ctx->queue_family;
    if (VkResult r = vkCreateCommandPool(dev(), &pi, nullptr, &pool); r != VK_SUCCESS)
      return fail("vkCreateCommandPool", r);
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = pool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    if (VkResult r = vkAllocateCommandBuffers(dev(), &ai, &cmd); r != VK_SUCCESS)
      return fail("vkAllocateCommandBuffers", r);
    VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    if (VkResult r = vkCreateFence(dev(), &fi, nullptr, &fence); r != VK_SUCCESS)
      return fail("vkCreateFence", r);
    VkShaderModuleCreateInfo si{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    si.codeSize = sizeof(k_scene_vert_spv);
    si.pCode = k_scene_vert_spv;
    if (VkResult r = vkCreateShaderModule(dev(), &si, nullptr, &vs); r != VK_SUCCESS)
      return fail("vkCreateShaderModule", r);
    si.codeSize = sizeof(k_scene_frag_spv);
    si.pCode = k_scene_frag_spv;
    if (VkResult r = vkCreateShaderModule(dev(), &si, nullptr, &fs); r != VK_SUCCESS)
      return fail("vkCreateShaderModule", r);
    VkPushConstantRange pc{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                           sizeof(PushConstants)};
    VkPipelineLayoutCreateInfo li{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    li.pushConstantRangeCount = 1;
    li.pPushConstantRanges = &pc;
    if (VkResult r = vkCreatePipelineLayout(dev(), &li, nullptr, &layout); r != VK_SUCCESS)
      return fail("vkCreatePipelineLayout", r);
    // MSAA: the largest supported count not above the request.
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(ctx->physical, &props);
    const VkSampleCountFlags ok =
        props.limits.framebufferColorSampleCounts & props.limits.framebufferDepthSampleCounts;
    samples = 1;
    for (int s : {8, 4, 2})
      if (s <= want_samples && (ok & static_cast<VkSampleCountFlags>(s))) {
        samples = s;
        break;
      }
    return {};
  }

  // The atlas image, sampler, descriptor, shaders and pipeline layout of the panel.
  Status text_create_gpu() {
    TextGpu& t = text;
    if (Status s = make_image(t.atlas, static_cast<uint32_t>(t.font.width),
                              static_cast<uint32_t>(t.font.height), VK_FORMAT_R8_UNORM,
                              VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                              VK_IMAGE_ASPECT_COLOR_BIT, 1);
        !s)
      return s;
    if (Status s = ensure_buffer(t.staging, t.font.alpha.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
        !s)
      return s;
    std::memcpy(t.staging.mapped, t.font.alpha.data(), t.font.alpha.size());
    VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    si.magFilter = si.minFilter = VK_FILTER_LINEAR;
    si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    if (VkResult r = vkCreateSampler(dev(), &si, nullptr, &t.sampler); r != VK_SUCCESS)
      return fail("vkCreateSampler", r);
    VkDescriptorSetLayoutBinding b{0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1,
                                   VK_SHADER_STAGE_FRAGMENT_BIT, nullptr};
    VkDescriptorSetLayoutCreateInfo li{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    li.bindingCount = 1;
    li.pBindings = &b;
    if (VkResult r = vkCreateDescriptorSetLayout(dev(), &li, nullptr, &t.set_layout);
        r != VK_SUCCESS)
      return fail("vkCreateDescriptorSetLayout", r);
    VkDescriptorPoolSize ps{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1};
    VkDescriptorPoolCreateInfo pi{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pi.maxSets = 1;
    pi.poolSizeCount = 1;
    pi.pPoolSizes = &ps;
    if (VkResult r = vkCreateDescriptorPool(dev(), &pi, nullptr, &t.pool); r != VK_SUCCESS)
      return fail("vkCreateDescriptorPool", r);
    VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    ai.descriptorPool = t.pool;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &t.set_layout;
    if (VkResult r = vkAllocateDescriptorSets(dev(), &ai, &t.set); r != VK_SUCCESS)
      return fail("vkAllocateDescriptorSets", r);
    VkDescriptorImageInfo ii{t.sampler, t.atlas.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = t.set;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    w.pImageInfo = &ii;
    vkUpdateDescriptorSets(dev(), 1, &w, 0, nullptr);
    return text_create_layout();
  }

  Status text_create_layout() {
    TextGpu& t = text;
    VkShaderModuleCreateInfo si{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    si.codeSize = sizeof(k_text_vert_spv);
    si.pCode = k_text_vert_spv;
    if (VkResult r = vkCreateShaderModule(dev(), &si, nullptr, &t.vs); r != VK_SUCCESS)
      return fail("vkCreateShaderModule (text)", r);
    si.codeSize = sizeof(k_text_frag_spv);
    si.pCode = k_text_frag_spv;
    if (VkResult r = vkCreateShaderModule(dev(), &si, nullptr, &t.fs); r != VK_SUCCESS)
      return fail("vkCreateShaderModule (text)", r);
    VkPushConstantRange pc{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                           sizeof(TextPushConstants)};
    VkPipelineLayoutCreateInfo li{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    li.setLayoutCount = 1;
    li.pSetLayouts = &t.set_layout;
    li.pushConstantRangeCount = 1;
    li.pPushConstantRanges = &pc;
    if (VkResult r = vkCreatePipelineLayout(dev(), &li, nullptr, &t.layout); r != VK_SUCCESS)
      return fail("vkCreatePipelineLayout (text)", r);
    return {};
  }

  // Before recording: the font (once), the GPU objects (once) and the panel's quads (when its
  // version changed). A font that does not load leaves the panel out (text.error says why).
  Status text_prepare() {
    TextGpu& t = text;
    if (t.panel.lines.empty()) return {};
    if (!t.font_tried) {
      t.font_tried = true;
      auto font = load_font_atlas(t.font_path.empty() ? default_font_path() : t.font_path);
      if (!font) {
        t.error = font.error();
        return {};
      }
      t.font = std::move(*font);
      if (Status s = text_create_gpu(); !s) {
        t.error = "text: " + s.error;  // the scene is still drawn, without the panel
        return {};
      }
    }
    if (!t.error.empty() || (t.built && t.built_version == t.panel.version)) return {};
    const TextMesh m = build_text_panel(t.font, t.panel.lines, t.panel.style);
    const VkDeviceSize vbytes = std::max<size_t>(m.vertices.size(), 1) * sizeof(TextVertex);
    const VkDeviceSize ibytes = std::max<size_t>(m.indices.size(), 1) * sizeof(uint32_t);
    if (Status s = ensure_buffer(t.vb, vbytes, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT); !s) return s;
    if (Status s = ensure_buffer(t.ib, ibytes, VK_BUFFER_USAGE_INDEX_BUFFER_BIT); !s) return s;
    std::memcpy(t.vb.mapped, m.vertices.data(), m.vertices.size() * sizeof(TextVertex));
    std::memcpy(t.ib.mapped, m.indices.data(), m.indices.size() * sizeof(uint32_t));
    t.count = static_cast<uint32_t>(m.indices.size());
    t.height = m.height;
    t.built = true;
    t.built_version = t.panel.version;
    stats.text_rebuilt = true;
    return {};
  }

  bool text_drawn() const { return !text.panel.lines.empty() && text.error.empty() && text.built; }

  // In the frame's command buffer before any pass: the atlas from the staging buffer (once).
  void text_record_upload() {
    TextGpu& t = text;
    if (!text_drawn() || t.atlas_uploaded) return;
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = t.atlas.image;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                         0, nullptr, 0, nullptr, 1, &b);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {static_cast<uint32_t>(t.font.width), static_cast<uint32_t>(t.font.height),
                          1};
    vkCmdCopyBufferToImage(cmd, t.staging.buffer, t.atlas.image,
                           VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.newLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
                         0, 0, nullptr, 0, nullptr, 1, &b);
    t.atlas_uploaded = true;
  }

  // A triangle-list pipeline, two-sided (the cloth is; everything else is cheap enough), at the
  // renderer's sample count, one colour attachment, dynamic viewport and scissor: the scene's and
  // the panel's pipelines differ only in what is passed in.
  sim::Result<VkPipeline> make_pipeline(const VkPipelineShaderStageCreateInfo (&stages)[2],
                                        const VkPipelineVertexInputStateCreateInfo& vin,
                                        const VkPipelineDepthStencilStateCreateInfo& ds,
                                        const VkPipelineColorBlendAttachmentState& cba,
                                        VkPipelineLayout pipeline_layout, VkRenderPass rp,
                                        const char* what) {
    VkPipelineInputAssemblyStateCreateInfo ia{
        VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    ia.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    VkPipelineViewportStateCreateInfo vp{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    vp.viewportCount = 1;
    vp.scissorCount = 1;
    VkPipelineRasterizationStateCreateInfo rs{
        VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    rs.polygonMode = VK_POLYGON_MODE_FILL;
    rs.cullMode = VK_CULL_MODE_NONE;
    rs.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    rs.lineWidth = 1.0f;
    VkPipelineMultisampleStateCreateInfo ms{
        VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    ms.rasterizationSamples = static_cast<VkSampleCountFlagBits>(samples);
    VkPipelineColorBlendStateCreateInfo cb{
        VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
    cb.attachmentCount = 1;
    cb.pAttachments = &cba;
    VkDynamicState dyn[2] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dsi{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
    dsi.dynamicStateCount = 2;
    dsi.pDynamicStates = dyn;
    VkGraphicsPipelineCreateInfo gi{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    gi.stageCount = 2;
    gi.pStages = stages;
    gi.pVertexInputState = &vin;
    gi.pInputAssemblyState = &ia;
    gi.pViewportState = &vp;
    gi.pRasterizationState = &rs;
    gi.pMultisampleState = &ms;
    gi.pDepthStencilState = &ds;
    gi.pColorBlendState = &cb;
    gi.pDynamicState = &dsi;
    gi.layout = pipeline_layout;
    gi.renderPass = rp;
    VkPipeline p = VK_NULL_HANDLE;
    if (VkResult r = vkCreateGraphicsPipelines(dev(), VK_NULL_HANDLE, 1, &gi, nullptr, &p);
        r != VK_SUCCESS)
      return sim::Error{fail(std::string("vkCreateGraphicsPipelines (") + what + ")", r).error};
    return p;
  }

  sim::Result<VkPipeline> text_pipeline_for(VkFormat fmt, VkRenderPass rp, VkFormat depth_fmt) {
    const auto key = std::make_tuple(fmt, samples, depth_fmt);
    if (auto it = text.pipelines.find(key); it != text.pipelines.end()) return it->second;
    VkPipelineShaderStageCreateInfo stages[2]{};
    stages[0].sType = stages[1].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
    stages[0].module = text.vs;
    stages[0].pName = "main";
    stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
    stages[1].module = text.fs;
    stages[1].pName = "main";
    VkVertexInputBindingDescription binding{0, sizeof(TextVertex), VK_VERTEX_INPUT_RATE_VERTEX};
    VkVertexInputAttributeDescription attrs[3] = {
        {0, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(TextVertex, pos)},
        {1, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(TextVertex, uv)},
        {2, 0, VK_FORMAT_R32G32B32A32_SFLOAT, offsetof(TextVertex, color)}};
    VkPipelineVertexInputStateCreateInfo vin{
        VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    vin.vertexBindingDescriptionCount = 1;
    vin.pVertexBindingDescriptions = &binding;
    vin.vertexAttributeDescriptionCount = 3;
    vin.pVertexAttributeDescriptions = attrs;
    // Over everything, and no depth written: the panel is not a surface of the scene.
    VkPipelineDepthStencilStateCreateInfo ds{
        VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
    VkPipelineColorBlendAttachmentState cba{};
    cba.blendEnable = VK_TRUE;
    cba.srcColorBlendFactor = VK_BLEND_FACTOR_SRC_ALPHA;
    cba.dstColorBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
    cba.colorBlendOp = VK_BLEND_OP_ADD;
    cba.srcAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
    cba.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
    cba.alphaBlendOp = VK_BLEND_OP_ADD;
    cba.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                         VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
    auto p = make_pipeline(stages, vin, ds, cba, text.layout, rp, "text");
    if (p) text.pipelines[key] = *p;
    return p;
  }

  // Inside a view's last pass: the panel over what is drawn (viewport and scissor are set).
  Status text_record_draw(const View& view, VkFormat fmt, VkRenderPass rp, VkFormat depth_fmt,
                          bool encode) {
    if (!text_drawn()) return {};
    auto pipe = text_pipeline_for(fmt, rp, depth_fmt);
    if (!pipe) return Status{pipe.error()};
    TextPushConstants pc{};
    const Mat4f mvp = view.view_proj() * head_locked_panel(text.panel.head, text.height);
    std::memcpy(pc.mvp, mvp.data(), sizeof(pc.mvp));
    pc.flags[1] = encode ? 1 : 0;
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, *pipe);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, text.layout, 0, 1, &text.set, 0,
                            nullptr);
    vkCmdPushConstants(cmd, text.layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
                       0, sizeof(pc), &pc);
    const VkDeviceSize zero = 0;
    vkCmdBindVertexBuffers(cmd, 0, 1, &text.vb.buffer, &zero);
    vkCmdBindIndexBuffer(cmd, text.ib.buffer, 0, VK_INDEX_TYPE_UINT32);
    vkCmdDrawIndexed(cmd, text.count, 1, 0, 0, 0);
    return {};
  }

  void text_destroy() {
    TextGpu& t = text;
    for (auto& [k, p] : t.pipelines) vkDestroyPipeline(dev(), p, nullptr);
    t.pipelines.clear();
    if (t.layout) vkDestroyPipelineLayout(dev(), t.layout, nullptr);
    if (t.pool) vkDestroyDescriptorPool(dev(), t.pool, nullptr);
    if (t.set_layout) vkDestroyDescriptorSetLayout(dev(), t.set_layout, nullptr);
    if (t.sampler) vkDestroySampler(dev(), t.sampler, nullptr);
    if (t.vs) vkDestroyShaderModule(dev(), t.vs, nullptr);
    if (t.fs) vkDestroyShaderModule(dev(), t.fs, nullptr);
    for (Buffer* b : {&t.staging, &t.vb, &t.ib}) destroy_buffer(*b);
    destroy_attachment(t.atlas);
    t.layout = VK_NULL_HANDLE;
    t.pool = VK_NULL_HANDLE;
    t.set_layout = VK_NULL_HANDLE;
    t.sampler = VK_NULL_HANDLE;
    t.vs = t.fs = VK_NULL_HANDLE;
  }

  void destroy() {
    if (!ctx || !ctx->device) return;
    vkDeviceWaitIdle(dev());
    forget_targets();
    text_destroy();
    for (auto& [k, a] : attachments) {
      destroy_attachment(a.first);
      destroy_attachment(a.second);
    }
    attachments.clear();
    destroy_attachment(offscreen);
    for (Buffer* b : {&readback, &static_vb, &static_ib, &cloth_vb, &cloth_ib, &dyn_vb, &dyn_ib})
      destroy_buffer(*b);
    cloth_valid = false;
    for (auto& [k, p] : pipelines) vkDestroyPipeline(dev(), p, nullptr);
    pipelines.clear();
    for (auto& [k, p] : passes) vkDestroyRenderPass(dev(), p, nullptr);
    passes.clear();
    if (layout) vkDestroyPipelineLayout(dev(), layout, nullptr);
    if (vs) vkDestroyShaderModule(dev(), vs, nullptr);
    if (fs) vkDestroyShaderModule(dev(), fs, nullptr);
    if (fence) vkDestroyFence(dev(), fence, nullptr);
    if (pool) vkDestroyCommandPool(dev(), pool, nullptr);
    layout = VK_NULL_HANDLE;
    vs = fs = VK_NULL_HANDLE;
    fence = VK_NULL_HANDLE;
    pool = VK_NULL_HANDLE;
  }

  void forget_targets() {
    for (auto& [k, t] : targets) {
      if (t.framebuffer) vkDestroyFramebuffer(dev(), t.framebuffer, nullptr);
      if (t.view) vkDestroyImageView(dev(), t.view, nullptr);
      if (t.depth_view) vkDestroyImageView(dev(), t.depth_view, nullptr);
      if (t.overlay_framebuffer) vkDestroyFramebuffer(dev(), t.overlay_framebuffer, nullptr);
    }
    targets.clear();
  }

  sim::Result<VkRenderPass> pass_for(VkFormat fmt, VkImageLayout final_layout, VkFormat depth_fmt,
                                     PassKind kind) {
    const auto key = std::make_tuple(fmt, samples, final_layout, depth_fmt, static_cast<int>(kind));
    if (auto it = passes.find(key); it != passes.end()) return it->second;
    const auto s = static_cast<VkSampleCountFlagBits>(samples);
    std::vector<VkAttachmentDescription> att;
    VkAttachmentDescription color{};
    color.format = fmt;
    color.samples = s;
    color.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    color.storeOp = samples > 1 ? VK_ATTACHMENT_STORE_OP_DONT_CARE : VK_ATTACHMENT_STORE_OP_STORE;
    color.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    color.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    color.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    color.finalLayout = samples > 1 ? VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL : final_layout;
    if (kind == kScene) color.finalLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    if (kind == kOverlay) {
      color.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
      color.initialLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    }
    att.push_back(color);
    VkAttachmentDescription depth = color;
    depth.format = depth_fmt;
    depth.storeOp =
        kind == kScene ? VK_ATTACHMENT_STORE_OP_STORE : VK_ATTACHMENT_STORE_OP_DONT_CARE;
    depth.initialLayout = kind == kOverlay ? VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL
                                           : VK_IMAGE_LAYOUT_UNDEFINED;
    // kScene: copied from next (then left for the caller in DEPTH_STENCIL_ATTACHMENT_OPTIMAL).
    depth.finalLayout = kind == kScene ? VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL
                                       : VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
    att.push_back(depth);
    if (samples > 1) {
      VkAttachmentDescription resolve = color;
      resolve.samples = VK_SAMPLE_COUNT_1_BIT;
      resolve.loadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
      resolve.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
      resolve.finalLayout = final_layout;
      att.push_back(resolve);
    }
    VkAttachmentReference cref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    VkAttachmentReference dref{1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
    VkAttachmentReference rref{2, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    VkSubpassDescription sub{};
    sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    sub.colorAttachmentCount = 1;
    sub.pColorAttachments = &cref;
    sub.pDepthStencilAttachment = &dref;
    if (samples > 1) sub.pResolveAttachments = &rref;
    VkSubpassDependency deps[2]{};
    deps[0].srcSubpass = VK_SUBPASS_EXTERNAL;
    deps[0].dstSubpass = 0;
    deps[0].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT |
                           VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT |
                           VK_PIPELINE_STAGE_TRANSFER_BIT;
    deps[0].dstStageMask =
        VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT;
    deps[0].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT |
                            VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT |
                            VK_ACCESS_TRANSFER_READ_BIT;
    deps[0].dstAccessMask =
        VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    deps[1].srcSubpass = 0;
    deps[1].dstSubpass = VK_SUBPASS_EXTERNAL;
    deps[1].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
    deps[1].dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
    deps[1].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    deps[1].dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    VkRenderPassCreateInfo ri{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    ri.attachmentCount = static_cast<uint32_t>(att.size());
    ri.pAttachments = att.data();
    ri.subpassCount = 1;
    ri.pSubpasses = &sub;
    ri.dependencyCount = 2;
    ri.pDependencies = deps;
    VkRenderPass rp = VK_NULL_HANDLE;
    if (VkResult r = vkCreateRenderPass(dev(), &ri, nullptr, &rp); r != VK_SUCCESS)
      return sim::Error{fail("vkCreateRenderPass", r).error};
    passes[key] = rp;
    return rp;
  }

  // One pipeline per (format, samples, shading modes of the draw): the fragment shader is
  // specialised to the modes present (scene.frag kModes).
  // The render passes of one (format, samples, depth format) are compatible: any of them
  // makes the pipeline.
  sim::Result<VkPipeline> pipeline_for(VkFormat fmt, VkRenderPass rp, uint32_t modes,
                                       VkFormat depth_fmt) {
    const auto key = std::make_tuple(fmt, samples, modes, depth_fmt);
    if (auto it = pipelines.find(key); it != pipelines.end()) return it->second;
    const auto spec_value = static_cast<int32_t>(modes);
    const VkSpecializationMapEntry spec_entry{0, 0, sizeof(int32_t)};
    VkSpecializationInfo spec{};
    spec.mapEntryCount = 1;
    spec.pMapEntries = &spec_entry;
    spec.dataSize = sizeof(spec_value);
    spec.pData = &spec_value;
    VkPipelineShaderStageCreateInfo stages[2]{};
    stages[0].sType = stages[1].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
    stages[0].module = vs;
    stages[0].pName = "main";
    stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
    stages[1].module = fs;
    stages[1].pName = "main";
    stages[1].pSpecializationInfo = &spec;
    VkVertexInputBindingDescription binding{0, sizeof(Vertex), VK_VERTEX_INPUT_RATE_VERTEX};
    VkVertexInputAttributeDescription attrs[5] = {
        {0, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, pos)},
        {1, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, normal)},
        {2, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(Vertex, uv)},
        {3, 0, VK_FORMAT_R32G32B32A32_SFLOAT, offsetof(Vertex, color)},
        {4, 0, VK_FORMAT_R32G32B32A32_SFLOAT, offsetof(Vertex, aux)}};
    VkPipelineVertexInputStateCreateInfo vin{
        VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    vin.vertexBindingDescriptionCount = 1;
    vin.pVertexBindingDescriptions = &binding;
    vin.vertexAttributeDescriptionCount = 5;
    vin.pVertexAttributeDescriptions = attrs;
    VkPipelineDepthStencilStateCreateInfo ds{
        VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
    ds.depthTestEnable = VK_TRUE;
    ds.depthWriteEnable = VK_TRUE;
    ds.depthCompareOp = VK_COMPARE_OP_LESS_OR_EQUAL;
    VkPipelineColorBlendAttachmentState cba{};
    cba.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                         VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
    auto p = make_pipeline(stages, vin, ds, cba, layout, rp, "scene");
    if (p) pipelines[key] = *p;
    return p;
  }

  // The renderer's depth (depth_fmt: that of a caller's depth image it is copied from) and MSAA
  // colour.
  sim::Result<std::pair<Attachment, Attachment>*> attachments_for(
      uint32_t w, uint32_t h, VkFormat fmt, VkFormat depth_fmt = VK_FORMAT_D32_SFLOAT) {
    const auto key = std::make_tuple(w, h, fmt, samples, depth_fmt);
    if (auto it = attachments.find(key); it != attachments.end()) return &it->second;
    std::pair<Attachment, Attachment> a;
    Status st =
        make_image(a.first, w, h, depth_fmt,
                   VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                   VK_IMAGE_ASPECT_DEPTH_BIT, samples);
    if (st && samples > 1)
      st = make_image(a.second, w, h, fmt,
                      VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSIENT_ATTACHMENT_BIT,
                      VK_IMAGE_ASPECT_COLOR_BIT, samples);
    if (!st) {
      destroy_attachment(a.first);
      destroy_attachment(a.second);
      return sim::Error{st.error};
    }
    return &(attachments[key] = a);
  }

  // The target's framebuffer for rp; with a caller's depth image (rp kScene) also the kOverlay
  // framebuffer for overlay_rp (fb.overlay_framebuffer).
  sim::Result<TargetFb> framebuffer_for(const ColorTarget& t, VkRenderPass rp,
                                        VkRenderPass overlay_rp = VK_NULL_HANDLE) {
    const TargetKey key{t.image, t.array_layer,  t.width,       t.height,      t.format,
                        samples, t.final_layout, t.depth_image, t.depth_format};
    if (auto it = targets.find(key); it != targets.end()) return it->second;
    auto att = attachments_for(t.width, t.height, t.format,
                               t.depth_image ? t.depth_format : VK_FORMAT_D32_SFLOAT);
    if (!att) return sim::Error{att.error()};
    TargetFb fb;
    VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vi.image = t.image;
    vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vi.format = t.format;
    vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, t.array_layer, 1};
    if (VkResult r = vkCreateImageView(dev(), &vi, nullptr, &fb.view); r != VK_SUCCESS)
      return sim::Error{fail("vkCreateImageView (target)", r).error};
    VkImageView depth_view = (*att)->first.view;
    if (t.depth_image) {
      vi.image = t.depth_image;
      vi.format = t.depth_format;
      vi.subresourceRange = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, t.array_layer, 1};
      if (VkResult r = vkCreateImageView(dev(), &vi, nullptr, &fb.depth_view); r != VK_SUCCESS) {
        vkDestroyImageView(dev(), fb.view, nullptr);
        return sim::Error{fail("vkCreateImageView (depth target)", r).error};
      }
      depth_view = fb.depth_view;
    }
    std::vector<VkImageView> views;
    if (samples > 1)
      views = {(*att)->second.view, depth_view, fb.view};
    else
      views = {fb.view, depth_view};
    VkFramebufferCreateInfo fi{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    fi.renderPass = rp;
    fi.attachmentCount = static_cast<uint32_t>(views.size());
    fi.pAttachments = views.data();
    fi.width = t.width;
    fi.height = t.height;
    fi.layers = 1;
    if (VkResult r = vkCreateFramebuffer(dev(), &fi, nullptr, &fb.framebuffer); r != VK_SUCCESS) {
      vkDestroyImageView(dev(), fb.view, nullptr);
      if (fb.depth_view) vkDestroyImageView(dev(), fb.depth_view, nullptr);
      return sim::Error{fail("vkCreateFramebuffer", r).error};
    }
    if (t.depth_image) {
      const VkImageView ov[2] = {fb.view, (*att)->first.view};
      fi.renderPass = overlay_rp;
      fi.pAttachments = ov;
      if (VkResult r = vkCreateFramebuffer(dev(), &fi, nullptr, &fb.overlay_framebuffer);
          r != VK_SUCCESS) {
        vkDestroyFramebuffer(dev(), fb.framebuffer, nullptr);
        vkDestroyImageView(dev(), fb.view, nullptr);
        vkDestroyImageView(dev(), fb.depth_view, nullptr);
        return sim::Error{fail("vkCreateFramebuffer (overlay)", r).error};
      }
    }
    targets[key] = fb;
    return fb;
  }

  Status upload(const Mesh& m, Buffer& vb, Buffer& ib) {
    const VkDeviceSize vbytes = std::max<size_t>(m.vertices.size(), 1) * sizeof(Vertex);
    const VkDeviceSize ibytes = std::max<size_t>(m.indices.size(), 1) * sizeof(uint32_t);
    if (Status s = ensure_buffer(vb, vbytes, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT); !s) return s;
    if (Status s = ensure_buffer(ib, ibytes, VK_BUFFER_USAGE_INDEX_BUFFER_BIT); !s) return s;
    if (!m.vertices.empty())
      std::memcpy(vb.mapped, m.vertices.data(), m.vertices.size() * sizeof(Vertex));
    if (!m.indices.empty())
      std::memcpy(ib.mapped, m.indices.data(), m.indices.size() * sizeof(uint32_t));
    return {};
  }

  Status prepare_static(const sim::SceneSnapshot& snap, const DrawOptions& opt) {
    if (static_vb.buffer && cached_form == snap.form.get() && cached_floor == opt.floor_grid &&
        cached_spacing == opt.form_section_spacing && cached_angle_step == opt.form_angle_step &&
        cached_colour == opt.form_colour)
      return {};
    mesh.clear();
    if (snap.form) append_form(*snap.form, opt.form_section_spacing, opt, mesh);
    static_split = static_cast<uint32_t>(mesh.indices.size());
    if (opt.floor_grid) append_floor(mesh);
    if (Status s = upload(mesh, static_vb, static_ib); !s) return s;
    static_count = static_cast<uint32_t>(mesh.indices.size());
    static_modes[0] = modes_of(mesh, 0, static_split);
    static_modes[1] = modes_of(mesh, static_split, static_count);
    cached_form = snap.form.get();
    form_ref = snap.form;
    cached_floor = opt.floor_grid;
    cached_spacing = opt.form_section_spacing;
    cached_angle_step = opt.form_angle_step;
    cached_colour = opt.form_colour;
    return {};
  }

  // The shading modes (bit m = ShadeMode m) of the triangles indices[first, last) of m.
  static uint32_t modes_of(const Mesh& m, size_t first, size_t last) {
    uint32_t mask = 0;
    for (size_t i = first; i < last; ++i) {
      const int mode = static_cast<int>(m.vertices[m.indices[i]].aux[0] + 0.5f);
      if (mode >= 0 && mode < 31) mask |= 1u << mode;
    }
    return mask;
  }

  template <class T>
  static bool same(const std::vector<T>& a, const std::vector<T>& b) {
    return a.size() == b.size() &&
           (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
  }

  // Rebuilds and uploads the cloth's vertices unless the inputs equal the cached ones.
  // Returns whether it rebuilt; *upload_ms gets the copy time.
  sim::Result<bool> prepare_cloth(const sim::SceneSnapshot& snap, const DrawOptions& opt,
                                  double* upload_ms) {
    ClothInputs& c = cloth_in;
    const bool uses_strain = opt.colour_map == ColourMap::kStrain;
    const sim::DressForm* form = opt.colour_map == ColourMap::kEase ? snap.form.get() : nullptr;
    if (cloth_valid && cloth_vb.buffer && same(c.positions, snap.positions) &&
        same(c.normals, snap.normals) && same(c.material, snap.material) &&
        same(c.indices, snap.indices) && (!uses_strain || same(c.strain, snap.strain)) &&
        c.form == form && c.colour_map == opt.colour_map && c.strain_range == opt.strain_range &&
        c.ease_range == opt.ease_range && c.colour == opt.cloth_colour)
      return false;
    cloth_valid = false;
    mesh.clear();
    append_cloth(snap, opt, mesh);
    const auto t0 = Clock::now();
    if (Status s = upload(mesh, cloth_vb, cloth_ib); !s) return sim::Error{s.error};
    *upload_ms += ms_since(t0);
    cloth_count = static_cast<uint32_t>(mesh.indices.size());
    cloth_modes = modes_of(mesh, 0, mesh.indices.size());
    c.positions = snap.positions;
    c.normals = snap.normals;
    c.material = snap.material;
    c.indices = snap.indices;
    if (uses_strain)
      c.strain = snap.strain;
    else
      c.strain.clear();
    c.form = form;
    c.colour_map = opt.colour_map;
    c.strain_range = opt.strain_range;
    c.ease_range = opt.ease_range;
    c.colour = opt.cloth_colour;
    cloth_valid = true;
    return true;
  }

  // Between the kScene and kOverlay passes: the caller's depth (TRANSFER_SRC_OPTIMAL) into the
  // renderer's `own` depth image; both then in DEPTH_STENCIL_ATTACHMENT_OPTIMAL.
  void copy_depth(const ColorTarget& t, VkImage own) {
    auto barrier = [&](VkImage image, uint32_t layer, VkImageLayout from, VkImageLayout to,
                       VkAccessFlags src, VkAccessFlags dst, VkPipelineStageFlags src_stage,
                       VkPipelineStageFlags dst_stage) {
      VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
      b.oldLayout = from;
      b.newLayout = to;
      b.srcAccessMask = src;
      b.dstAccessMask = dst;
      b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
      b.image = image;
      b.subresourceRange = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, layer, 1};
      vkCmdPipelineBarrier(cmd, src_stage, dst_stage, 0, 0, nullptr, 0, nullptr, 1, &b);
    };
    const VkAccessFlags depth_rw =
        VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    const VkPipelineStageFlags tests =
        VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
    barrier(t.depth_image, t.array_layer, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
            VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
            VK_ACCESS_TRANSFER_READ_BIT, tests, VK_PIPELINE_STAGE_TRANSFER_BIT);
    barrier(own, 0, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0,
            VK_ACCESS_TRANSFER_WRITE_BIT, tests, VK_PIPELINE_STAGE_TRANSFER_BIT);
    VkImageCopy region{};
    region.srcSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, t.array_layer, 1};
    region.dstSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1};
    region.extent = {t.width, t.height, 1};
    vkCmdCopyImage(cmd, t.depth_image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, own,
                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    barrier(t.depth_image, t.array_layer, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
            VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL, VK_ACCESS_TRANSFER_READ_BIT, 0,
            VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT);
    barrier(own, 0, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
            VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL, VK_ACCESS_TRANSFER_WRITE_BIT,
            depth_rw, VK_PIPELINE_STAGE_TRANSFER_BIT, tests);
  }

  Status check_targets(const ViewTarget* views, int count) const {
    if (lost) return Status{"vulkan: the device was lost earlier; recreate the renderer"};
    if (!views || count <= 0) return Status{"render: no view to draw"};
    for (int i = 0; i < count; ++i) {
      const ColorTarget& t = views[i].target;
      if (!t.image || t.width == 0 || t.height == 0)
        return Status{"render: target image is null or has zero size"};
      if (t.depth_image && samples > 1)
        return Status{"render: a caller's depth image needs samples 1"};
      if (t.depth_image && t.depth_format != VK_FORMAT_D32_SFLOAT &&
          t.depth_format != VK_FORMAT_D16_UNORM)
        return Status{"render: the depth image must be D32_SFLOAT or D16_UNORM"};
    }
    return {};
  }

  // The target's colour (TRANSFER_SRC_OPTIMAL) into the readback buffer, visible to the host.
  void record_readback(const ColorTarget& t) {
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, t.array_layer, 1};
    region.imageExtent = {t.width, t.height, 1};
    vkCmdCopyImageToBuffer(cmd, t.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback.buffer, 1,
                           &region);
    VkBufferMemoryBarrier bar{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
    bar.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    bar.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    bar.srcQueueFamilyIndex = bar.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    bar.buffer = readback.buffer;
    bar.size = VK_WHOLE_SIZE;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 0,
                         nullptr, 1, &bar, 0, nullptr);
  }

  // Records and submits one frame into every target of `views` (the geometry is built and
  // uploaded once); with `readback_copy` (one view) also copies the result into the readback
  // buffer. Waits for completion.
  Status draw(const sim::SceneSnapshot& snap, const ViewTarget* views, int count,
              const DrawOptions& opt, bool readback_copy) {
    if (Status s = check_targets(views, count); !s) return s;
    const double cpu0 = thread_cpu_ms();
    auto t0 = Clock::now();
    stats = FrameStats{};
    stats.views = count;
    if (Status s = prepare_static(snap, opt); !s) return s;
    auto rebuilt = prepare_cloth(snap, opt, &stats.upload_ms);
    if (!rebuilt) return Status{rebuilt.error()};
    stats.cloth_rebuilt = *rebuilt;
    mesh.clear();
    append_decorations(snap, opt, mesh);
    append_hand_overlays(snap, opt, mesh);
    const auto dyn_count = static_cast<uint32_t>(mesh.indices.size());
    const uint32_t dyn_modes = modes_of(mesh, 0, mesh.indices.size());
    // The draws, roughly near to far (hands and decorations, cloth, form, floor) so that
    // lavapipe's early depth test skips the shading of hidden pixels; each with a pipeline
    // specialised to its shading modes.
    struct DrawRange {
      const Buffer *vb, *ib;
      uint32_t first, count, modes;
    };
    const DrawRange ranges[4] = {
        {&dyn_vb, &dyn_ib, 0, dyn_count, dyn_modes},
        {&cloth_vb, &cloth_ib, 0, cloth_count, cloth_modes},
        {&static_vb, &static_ib, 0, static_split, static_modes[0]},
        {&static_vb, &static_ib, static_split, static_count - static_split, static_modes[1]}};
    stats.triangles = (static_count + cloth_count + dyn_count) / 3;
    const auto t_up = Clock::now();
    if (Status s = upload(mesh, dyn_vb, dyn_ib); !s) return s;
    stats.upload_ms += ms_since(t_up);
    stats.build_ms = ms_since(t0) - stats.upload_ms;
    t0 = Clock::now();

    if (Status s = text_prepare(); !s) return s;
    vkResetCommandBuffer(cmd, 0);
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    if (VkResult r = vkBeginCommandBuffer(cmd, &bi); r != VK_SUCCESS)
      return fail("vkBeginCommandBuffer", r);
    text_record_upload();
    for (int i = 0; i < count; ++i) {
      const View& view = views[i].view;
      const ColorTarget& t = views[i].target;
      const bool stored = t.depth_image != VK_NULL_HANDLE;
      const VkFormat depth_fmt = stored ? t.depth_format : VK_FORMAT_D32_SFLOAT;
      auto rp = pass_for(t.format, t.final_layout, depth_fmt, stored ? kScene : kWhole);
      if (!rp) return Status{rp.error()};
      sim::Result<VkRenderPass> overlay_rp = VkRenderPass{VK_NULL_HANDLE};
      if (stored) overlay_rp = pass_for(t.format, t.final_layout, depth_fmt, kOverlay);
      if (!overlay_rp) return Status{overlay_rp.error()};
      auto fb = framebuffer_for(t, *rp, *overlay_rp);
      if (!fb) return Status{fb.error()};

      const PushConstants pc = push_constants(snap, view, t.format, opt);

      const std::array<VkClearValue, 3> clears = clear_values(opt, pc.flags[1] != 0);
      VkRenderPassBeginInfo rbi{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
      rbi.renderPass = *rp;
      rbi.framebuffer = fb->framebuffer;
      rbi.renderArea = {{0, 0}, {t.width, t.height}};
      rbi.clearValueCount = samples > 1 ? 3 : 2;
      rbi.pClearValues = clears.data();
      vkCmdBeginRenderPass(cmd, &rbi, VK_SUBPASS_CONTENTS_INLINE);
      VkViewport viewport{0, 0, static_cast<float>(t.width), static_cast<float>(t.height), 0, 1};
      VkRect2D scissor{{0, 0}, {t.width, t.height}};
      vkCmdSetViewport(cmd, 0, 1, &viewport);
      vkCmdSetScissor(cmd, 0, 1, &scissor);
      vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                         sizeof(pc), &pc);  // same layout for every pipeline below
      const VkDeviceSize zero = 0;
      VkPipeline bound = VK_NULL_HANDLE;
      const Buffer* bound_vb = nullptr;
      auto draw_ranges = [&](std::initializer_list<int> which) -> Status {
        for (int k : which) {
          const DrawRange& d = ranges[k];
          if (!d.count) continue;
          auto pipe = pipeline_for(t.format, *rp, d.modes, depth_fmt);
          if (!pipe) return Status{pipe.error()};
          if (*pipe != bound) {
            vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, *pipe);
            bound = *pipe;
          }
          if (d.vb != bound_vb) {
            vkCmdBindVertexBuffers(cmd, 0, 1, &d.vb->buffer, &zero);
            vkCmdBindIndexBuffer(cmd, d.ib->buffer, 0, VK_INDEX_TYPE_UINT32);
            bound_vb = d.vb;
          }
          vkCmdDrawIndexed(cmd, d.count, 1, d.first, 0, 0);
        }
        return Status{};
      };
      // A caller's depth holds the scene only (cloth, form, floor): the hands and markers are
      // drawn in a second pass over a copy of it, so the depth under a hand is the surface it
      // is over, not its own pointer (a compositor reprojecting the scene, a desk runtime
      // placing the hand on it). The colour is the same as in one pass.
      Status drawn = draw_ranges({1, 2, 3});
      if (drawn && stored) {
        vkCmdEndRenderPass(cmd);
        copy_depth(t, (*attachments_for(t.width, t.height, t.format, depth_fmt))->first.image);
        rbi.renderPass = *overlay_rp;
        rbi.framebuffer = fb->overlay_framebuffer;
        rbi.clearValueCount = 0;
        rbi.pClearValues = nullptr;
        vkCmdBeginRenderPass(cmd, &rbi, VK_SUBPASS_CONTENTS_INLINE);
        vkCmdSetViewport(cmd, 0, 1, &viewport);
        vkCmdSetScissor(cmd, 0, 1, &scissor);
      }
      // The panel over the scene, in the pass whose depth is not the caller's; then the hands
      // and markers over both, so the panel never hides the hand the user steers.
      if (drawn)
        drawn = text_record_draw(view, t.format, stored ? *overlay_rp : *rp, depth_fmt,
                                 pc.flags[1] != 0);
      if (drawn) {
        vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
                           0, sizeof(pc), &pc);
        bound = VK_NULL_HANDLE;
        bound_vb = nullptr;
        drawn = draw_ranges({0});
      }
      if (!drawn) {
        vkCmdEndRenderPass(cmd);
        vkEndCommandBuffer(cmd);
        return drawn;
      }
      vkCmdEndRenderPass(cmd);
      if (readback_copy && i == 0) record_readback(t);
    }
    if (VkResult r = vkEndCommandBuffer(cmd); r != VK_SUCCESS) return fail("vkEndCommandBuffer", r);
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd;
    vkResetFences(dev(), 1, &fence);
    if (VkResult r = vkQueueSubmit(ctx->queue, 1, &si, fence); r != VK_SUCCESS)
      return fail("vkQueueSubmit", r);
    stats.submit_ms = ms_since(t0) + stats.upload_ms;
    t0 = Clock::now();
    constexpr uint64_t kTimeoutNs = 60ull * 1000 * 1000 * 1000;
    VkResult r = vkWaitForFences(dev(), 1, &fence, VK_TRUE, kTimeoutNs);
    stats.wait_ms = ms_since(t0);
    stats.thread_cpu_ms = thread_cpu_ms() - cpu0;
    if (r == VK_TIMEOUT) {
      lost = true;  // the command buffer may still be pending: nothing can be reused safely
      return Status{"vulkan: frame did not finish within 60 s (treated as a lost device)"};
    }
    if (r != VK_SUCCESS) return fail("vkWaitForFences", r);
    return {};
  }

  sim::Result<Image> draw_offscreen(const sim::SceneSnapshot& snap, const View& view, int w, int h,
                                    const DrawOptions& opt) {
    if (lost) return sim::Error{"vulkan: the device was lost earlier; recreate the renderer"};
    if (w <= 0 || h <= 0 || w > 16384 || h > 16384)
      return sim::Error{"render: image size " + std::to_string(w) + "x" + std::to_string(h) +
                        " out of range (1..16384)"};
    const auto uw = static_cast<uint32_t>(w), uh = static_cast<uint32_t>(h);
    constexpr VkFormat kFormat = VK_FORMAT_R8G8B8A8_SRGB;
    if (uw != off_w || uh != off_h || !offscreen.image) {
      forget_targets();
      destroy_attachment(offscreen);
      if (Status s =
              make_image(offscreen, uw, uh, kFormat,
                         VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                         VK_IMAGE_ASPECT_COLOR_BIT, 1);
          !s)
        return sim::Error{s.error};
      off_w = uw;
      off_h = uh;
    }
    if (Status s =
            ensure_buffer(readback, VkDeviceSize(uw) * uh * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
        !s)
      return sim::Error{s.error};
    const ViewTarget vt{view, ColorTarget{offscreen.image, kFormat, uw, uh, 0,
                                          VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL}};
    if (Status s = draw(snap, &vt, 1, opt, true); !s) return sim::Error{s.error};
    Image img;
    img.width = w;
    img.height = h;
    img.rgba.resize(static_cast<size_t>(w) * h * 4);
    std::memcpy(img.rgba.data(), readback.mapped, img.rgba.size());
    return img;
  }
};

Renderer::Renderer() : impl_(std::make_unique<Impl>()) {}
Renderer::~Renderer() = default;

sim::Result<std::unique_ptr<Renderer>> Renderer::create(const RendererOptions& opt) {
  auto ctx = VulkanContext::create(opt.context);
  if (!ctx) return sim::Error{ctx.error()};
  std::unique_ptr<Renderer> r(new Renderer());
  r->impl_->ctx = std::move(*ctx);
  r->impl_->text.font_path = opt.font_path;
  if (Status s = r->impl_->init(opt.samples); !s) return sim::Error{s.error};
  return r;
}

sim::Result<std::unique_ptr<Renderer>> Renderer::create_on(const ExternalDevice& dev,
                                                           const RendererOptions& opt) {
  auto ctx = VulkanContext::adopt(dev);
  if (!ctx) return sim::Error{ctx.error()};
  std::unique_ptr<Renderer> r(new Renderer());
  r->impl_->ctx = std::move(*ctx);
  r->impl_->text.font_path = opt.font_path;
  if (Status s = r->impl_->init(opt.samples); !s) return sim::Error{s.error};
  return r;
}

Status Renderer::render(const sim::SceneSnapshot& snap, const View& view, const ColorTarget& t,
                        const DrawOptions& opt) {
  const ViewTarget vt{view, t};
  return impl_->draw(snap, &vt, 1, opt, false);
}

Status Renderer::render_views(const sim::SceneSnapshot& snap, const ViewTarget* views, int count,
                              const DrawOptions& opt) {
  return impl_->draw(snap, views, count, opt, false);
}

sim::Result<Image> Renderer::render_offscreen(const sim::SceneSnapshot& snap, const View& view,
                                              int width, int height, const DrawOptions& opt) {
  return impl_->draw_offscreen(snap, view, width, height, opt);
}

void Renderer::set_text_panel(const TextPanel& panel) {
  TextPanel& p = impl_->text.panel;
  if (panel.version != p.version || panel.lines.empty() != p.lines.empty()) p.lines = panel.lines;
  if (std::memcmp(&panel.style, &p.style, sizeof(PanelStyle)) != 0) impl_->text.built = false;
  p.version = panel.version;
  p.head = panel.head;
  p.style = panel.style;
}

const std::string& Renderer::text_error() const {
  return impl_->text.error;
}

void Renderer::forget_targets() {
  if (!impl_->lost) vkDeviceWaitIdle(impl_->dev());
  impl_->forget_targets();
}
ValidationCounts Renderer::validation() const {
  return impl_->ctx->validation();
}
const std::string& Renderer::device_name() const {
  return impl_->ctx->device_name;
}
bool Renderer::is_cpu_device() const {
  return impl_->ctx->is_cpu;
}
bool Renderer::device_lost() const {
  return impl_->lost;
}
const FrameStats& Renderer::last_frame() const {
  return impl_->stats;
}
VulkanContext& Renderer::context() {
  return *impl_->ctx;
}
void Renderer::simulate_device_lost() {
  impl_->lost = true;
}

}  // namespace drape::render
