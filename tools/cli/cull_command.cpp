// glint cull --depth DEPTH.exr --objects OBJECTS.json OUT.json [--reverse-z] [--stats]: the object
// occlusion cull (include/glint/object_cull.h) of a list of spheres and boxes against a depth image.
//
// OBJECTS.json (no other key is accepted, so a typo is an error, not a silent default):
//   {"view": [16 numbers, column-major], "proj": [16 numbers, column-major],
//    "objects": [{"sphere": [x, y, z, r]} | {"box": [minx, miny, minz, maxx, maxy, maxz]}, ...]}
// Numbers must be finite and within float range; r >= 0; min <= max. OUT.json:
//   {"total": N, "frustum_culled": a, "occluded": b, "visible": c,
//    "objects": ["visible" | "occluded" | "frustum", ...]}
// replaced atomically (io::AtomicOutputs), so a failed or killed run leaves no half-written file.
#include <glint/object_cull.h>
#include <glint/occlusion.h>

#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "core/barriers.h"
#include "core/resources.h"
#include "glint/gpu/object_cull.h"
#include "io/atomic_outputs.h"
#include "support/transfer.h"

namespace glint::cli {
namespace {

struct CullOptions {
  std::string depth, objects, output, device;
  bool reverse_z = false;
  bool stats = false;
};

// The largest OBJECTS.json read (about 100 bytes an object: ten million objects).
constexpr uint64_t kMaxObjectsFileBytes = uint64_t(1) << 30;

[[noreturn]] void bad(const std::string& path, const std::string& what) {
  throw Error(ErrorCode::invalid_argument, path + ": " + what);
}

float number(const std::string& path, const nlohmann::json& v, const std::string& where) {
  if (!v.is_number()) bad(path, where + " is not a number");
  const double d = v.get<double>();
  if (!std::isfinite(d) || std::abs(d) > double(FLT_MAX))
    bad(path, where + " = " + v.dump() + " is not a finite float");
  return static_cast<float>(d);
}

void numbers(const std::string& path, const nlohmann::json& v, const std::string& where, size_t n, float* out) {
  if (!v.is_array() || v.size() != n) bad(path, where + " must be an array of " + std::to_string(n) + " numbers");
  for (size_t i = 0; i < n; ++i) out[i] = number(path, v[i], where + "[" + std::to_string(i) + "]");
}

struct ObjectsFile {
  ObjectCullFrame frame;
  std::vector<GlintCullObject> objects;
};

ObjectsFile read_objects(const std::string& path, uint32_t max_objects) {
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(path, ec);
  if (ec) throw Error(ErrorCode::io_failure, path + ": cannot read: " + ec.message());
  if (bytes > kMaxObjectsFileBytes) bad(path, "file is " + std::to_string(bytes) + " bytes; at most 1 GiB is read");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::io_failure, path + ": cannot open");
  std::stringstream text;
  text << in.rdbuf();
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text.str());
  } catch (const nlohmann::json::parse_error& e) {
    bad(path, std::string("not JSON: ") + e.what());
  }
  if (!j.is_object()) bad(path, "top level must be an object with \"view\", \"proj\" and \"objects\"");
  for (const auto& [key, value] : j.items()) {
    if (key != "view" && key != "proj" && key != "objects") bad(path, "unknown key \"" + key + "\"");
  }
  for (const char* key : {"view", "proj", "objects"}) {
    if (!j.contains(key)) bad(path, std::string("missing \"") + key + "\"");
  }
  ObjectsFile f;
  numbers(path, j["view"], "view", 16, f.frame.view);
  numbers(path, j["proj"], "proj", 16, f.frame.proj);
  const auto& list = j["objects"];
  if (!list.is_array()) bad(path, "\"objects\" must be an array");
  if (list.size() > max_objects)
    bad(path, "\"objects\" holds " + std::to_string(list.size()) + "; at most " + std::to_string(max_objects));
  f.objects.resize(list.size());
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string at = "objects[" + std::to_string(i) + "]";
    const auto& o = list[i];
    if (!o.is_object() || o.size() != 1 || !(o.contains("sphere") || o.contains("box"))) {
      bad(path, at + " must be {\"sphere\": [x, y, z, r]} or {\"box\": [minx, miny, minz, maxx, maxy, maxz]}");
    }
    GlintCullObject& g = f.objects[i];
    g = {};
    if (o.contains("sphere")) {
      g.kind = GLINT_OBJECT_SPHERE;
      numbers(path, o["sphere"], at + ".sphere", 4, g.sphere_or_min);
      if (!(g.sphere_or_min[3] >= 0))
        bad(path, at + ".sphere[3] = " + o["sphere"][3].dump() + ": the radius must be >= 0");
    } else {
      g.kind = GLINT_OBJECT_BOX;
      float b[6];
      numbers(path, o["box"], at + ".box", 6, b);
      for (int a = 0; a < 3; ++a) {
        if (!(b[a] <= b[a + 3])) {
          bad(path, at + ".box[" + std::to_string(a) + "] = " + o["box"][a].dump() + " exceeds the max .box[" +
                        std::to_string(a + 3) + "] = " + o["box"][a + 3].dump());
        }
        g.sphere_or_min[a] = b[a];
        g.box_max[a] = b[a + 3];
      }
    }
  }
  f.frame.count = static_cast<uint32_t>(f.objects.size());
  return f;
}

const char* state_name(uint32_t s) {
  switch (s) {
    case GLINT_OBJECT_STATE_VISIBLE:
      return "visible";
    case GLINT_OBJECT_STATE_OCCLUDED:
      return "occluded";
    case GLINT_OBJECT_STATE_FRUSTUM:
      return "frustum";
  }
  throw Error(ErrorCode::vulkan_failure, "the cull left object state " + std::to_string(s));
}

void run(const CullOptions& o) {
  check_output_path(o.output);
  const io::ExrChannel depth_in = read_depth_exr(o.depth);
  const uint32_t max_objects = 1u << 24;
  ObjectsFile file = read_objects(o.objects, max_objects);
  const uint32_t n = file.frame.count;
  const VkExtent2D extent{depth_in.width, depth_in.height};
  Context context = make_context(o.device);

  HiZConfig hc;
  hc.extent = extent;
  hc.format = VK_FORMAT_D32_SFLOAT;
  hc.reversed_z = o.reverse_z;
  HiZPyramid hiz(context, hc);
  ObjectCullConfig cc;
  cc.max_objects = std::max(1u, n);
  cc.capacity = std::max(1u, n);
  cc.reversed_z = o.reverse_z;
  ObjectCuller culler(context, cc);

  detail::OwnedImage depth(context, extent, VK_FORMAT_D32_SFLOAT,
                           VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
  const detail::OwnedBuffer depth_up = detail::make_upload_staging_r32(context, depth.image(), depth_in.values);
  const VkBufferUsageFlags usage =
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT;
  auto host_buffer = [&](VkDeviceSize bytes) {
    bytes = std::max<VkDeviceSize>(bytes, 16);
    return detail::OwnedBuffer(context, bytes, usage, true);
  };
  auto view = [&](const detail::OwnedBuffer& b) {
    return Buffer{b.buffer(), 0, b.size(), usage, VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_WRITE_BIT};
  };
  detail::OwnedBuffer objects = host_buffer(VkDeviceSize(n) * sizeof(GlintCullObject));
  if (n) std::memcpy(objects.mapped(), file.objects.data(), size_t(n) * sizeof(GlintCullObject));
  objects.flush();
  detail::OwnedBuffer visibility = host_buffer(VkDeviceSize(n) * 4), list = host_buffer(VkDeviceSize(cc.capacity) * 4),
                      indirect = host_buffer(sizeof(GlintObjectCullIndirect)),
                      stats = host_buffer(sizeof(GlintObjectCullStats));
  ObjectCullBuffers buffers{view(objects), {}, view(visibility)};
  ObjectCullOutputs outputs{view(list), view(indirect), view(stats)};
  // Thrown here, before the submission, for a camera the cull does not accept.
  Profiler profiler(context);
  context.run_once([&](VkCommandBuffer cmd) {
    profiler.reset(cmd);
    profiler.mark(cmd, "start");
    detail::record_upload(cmd, depth_up, depth.image());
    hiz.record(cmd, depth.image(), &profiler);
    culler.record(cmd, hiz, depth.image(), file.frame, buffers, outputs, &profiler);
    detail::Barriers b;
    b.use(buffers.visibility, VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    b.use(outputs.stats, VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    b.flush(cmd);
  });
  visibility.invalidate();
  stats.invalidate();
  const auto* states = static_cast<const uint32_t*>(visibility.mapped());
  const GlintObjectCullStats st = *static_cast<const GlintObjectCullStats*>(stats.mapped());

  std::string out = "{\"total\": " + std::to_string(st.total) +
                    ", \"frustum_culled\": " + std::to_string(st.frustum_culled) +
                    ", \"occluded\": " + std::to_string(st.occluded) + ", \"visible\": " + std::to_string(st.visible) +
                    ", \"objects\": [";
  for (uint32_t i = 0; i < n; ++i) {
    if (i) out += ", ";
    out += std::string("\"") + state_name(states[i]) + "\"";
  }
  out += "]}\n";
  io::AtomicOutputs files;  // temporary, fsync, rename (README: every CLI output is replaced atomically)
  files.write(o.output, [&](const std::string& tmp) { io::write_text_file(tmp, out); });
  files.commit();
  std::printf("device: %s (%s)\n", context.info().name.c_str(), device_type_name(context.info().type));
  std::printf("input: %s, %ux%u; %u object%s from %s\n", o.depth.c_str(), extent.width, extent.height, n,
              n == 1 ? "" : "s", o.objects.c_str());
  std::printf("objects: %u total, %u frustum-culled, %u occluded, %u visible (%u invalid)\n", st.total,
              st.frustum_culled, st.occluded, st.visible, st.invalid);
  if (o.stats) print_stages(profiler);
  std::printf("wrote %s\n", o.output.c_str());
}

}  // namespace

Command add_cull_command(CLI::App& app) {
  auto o = std::make_shared<CullOptions>();
  CLI::App* sub =
      app.add_subcommand("cull", "Occlusion-cull bounding spheres and boxes against a depth image (on the GPU)");
  sub->add_option("--depth", o->depth,
                  "Depth OpenEXR file: one float channel named Z (else the first channel), values in [0, 1]")
      ->required();
  sub->add_option("--objects", o->objects,
                  "OBJECTS.json: {\"view\": [16], \"proj\": [16] (column-major, Vulkan perspective), \"objects\": "
                  "[{\"sphere\": [x,y,z,r]} | {\"box\": [minx,miny,minz,maxx,maxy,maxz]}]}")
      ->required();
  sub->add_option(
         "output", o->output,
         "Output JSON: {\"total\", \"frustum_culled\", \"occluded\", \"visible\", \"objects\": [state per object]}")
      ->required();
  sub->add_flag("--reverse-z", o->reverse_z, "Depth 1 is near and 0 far (reversed Z)");
  sub->add_flag("--stats", o->stats, "Print the GPU time of each stage");
  add_device_option(*sub, o->device);
  return {sub, [o] { run(*o); }};
}

}  // namespace glint::cli
