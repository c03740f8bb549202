// glint blur IN.exr OUT_PREFIX [--sigmas a,b,c]: the three blur-pyramid levels as
// OUT_PREFIX.blur1.exr, .blur2.exr, .blur3.exr at their level sizes.
// glint gauss IN.exr OUT.exr --sigma S [--method ...]: a same-size Gaussian blur; prints the
// method chosen and its expected error. Ranges are checked by the configs' validate().
#include <glint/blur.h>

#include <cstdio>
#include <memory>
#include <sstream>

#include "cli/commands.h"
#include "core/resources.h"
#include "io/atomic_outputs.h"
#include "io/exr_io.h"
#include "support/transfer.h"

namespace glint::cli {
namespace {

struct BlurOptions {
  std::string input;
  std::string prefix;
  std::string sigmas;
  std::string device;
  bool fp32 = false;
};

// "a,b,c" -> three floats; anything else is a one-line error naming the option.
std::array<float, 3> parse_sigmas(const std::string& text) {
  std::array<float, 3> s{};
  std::istringstream in(text);
  char comma1 = 0, comma2 = 0;
  std::string rest;
  if (!(in >> s[0] >> comma1 >> s[1] >> comma2 >> s[2]) || comma1 != ',' || comma2 != ',' || (in >> rest)) {
    throw Error(ErrorCode::invalid_argument,
                "--sigmas '" + text + "' is not three comma-separated numbers (e.g. 1.2,1.2,1.2)");
  }
  return s;
}

void run_blur(const BlurOptions& o) {
  BlurPyramidConfig config;
  if (!o.sigmas.empty()) config.sigma_texels = parse_sigmas(o.sigmas);
  config.precision = o.fp32 ? Precision::fp32 : Precision::fp16;
  config.validate();
  const std::string names[3] = {o.prefix + ".blur1.exr", o.prefix + ".blur2.exr", o.prefix + ".blur3.exr"};
  for (const std::string& n : names) check_output_path(n);

  const CpuImage input = io::read_exr(o.input);
  const Context context = make_context(o.device);
  BlurPyramid pyramid(context, config);
  pyramid.prepare({input.width, input.height});
  Profiler profiler(context);
  run_on_input(context, input, profiler,
               [&](VkCommandBuffer cmd, Image& source, Profiler* p) { pyramid.record(cmd, source, p); });
  print_device(context, o.input, input);
  print_stages(profiler);
  io::AtomicOutputs files;  // the three levels are replaced together, only once all are written
  VkExtent2D sizes[3];
  EffectiveSigma sigmas[3];
  for (uint32_t k = 1; k <= 3; ++k) {
    const CpuImage level = detail::download(context, pyramid.level(k));
    sizes[k - 1] = {level.width, level.height};
    sigmas[k - 1] = pyramid.effective_sigma_px(k);
    files.write(names[k - 1], [&](const std::string& tmp) { write_result_exr(tmp, level, o.fp32); });
  }
  files.commit();
  for (uint32_t k = 0; k < 3; ++k) {
    std::printf("wrote %s (%ux%u, sigma %.3g texels, effective sigma %.3f x %.3f input pixels)\n", names[k].c_str(),
                sizes[k].width, sizes[k].height, config.sigma_texels[k], sigmas[k].x_px, sigmas[k].y_px);
  }
}

struct GaussOptions {
  std::string input;
  std::string output;
  std::string device;
  std::string method = "auto";
  bool linear = false;
  bool fp32 = false;
  GaussianBlurConfig config;
};

BlurMethod method_from_name(const std::string& name) {
  if (name == "separable") return BlurMethod::separable;
  if (name == "pyramid") return BlurMethod::pyramid;
  if (name == "dual") return BlurMethod::dual;
  return BlurMethod::automatic;  // IsMember() has rejected anything else
}

void run_gauss(GaussOptions& o) {
  o.config.method = method_from_name(o.method);
  o.config.linear_sampling = o.linear;
  o.config.precision = o.fp32 ? Precision::fp32 : Precision::fp16;
  o.config.validate();
  check_output_path(o.output);

  const CpuImage input = io::read_exr(o.input);
  const VkExtent2D extent{input.width, input.height};
  const Context context = make_context(o.device);
  GaussianBlur blur(context, o.config);
  blur.prepare(extent);
  Profiler profiler(context);
  const CpuImage output = run_image_effect(
      context, input, profiler,
      [&](VkCommandBuffer cmd, Image& in, Image& out, Profiler* p) { blur.record(cmd, in, out, p); },
      o.fp32 ? VK_FORMAT_R32G32B32A32_SFLOAT : VK_FORMAT_R16G16B16A16_SFLOAT);
  print_device(context, o.input, input);
  const BlurChoice& c = blur.choice();
  std::printf("method: %s%s (asked: %s)", blur_method_name(c.method), c.linear_sampling ? " with linear sampling" : "",
              blur_method_name(o.config.method));
  if (c.method == BlurMethod::separable) std::printf(", %u taps", 2 * c.radius + 1);
  if (c.method == BlurMethod::pyramid)
    std::printf(", %u levels, sigma %.3f texels at the last", c.levels, c.level_sigma);
  if (c.method == BlurMethod::dual) std::printf(", %u levels, tap offset %.3f", c.levels, c.dual_offset);
  std::printf(", %u dispatches\n", c.dispatches);
  // Over the whole image, borders included: the pyramid and dual run on chains padded by the
  // clamp-to-edge extension at full resolution, the exact Gaussian's border rule (docs/BLUR.md,
  // "Borders").
  std::printf(
      "sigma: %.3f px asked, %.3f px effective; expected relative L2 error %.2e over the whole image "
      "(bound %.2e)\n",
      o.config.sigma_px, c.effective_sigma_px, c.expected_relative_error, o.config.max_relative_error);
  if (o.config.method == BlurMethod::automatic) std::printf("cost model estimate: %.3g us\n", c.estimated_us);
  print_stages(profiler);
  io::AtomicOutputs files;
  files.write(o.output, [&](const std::string& tmp) { write_result_exr(tmp, output, o.fp32); });
  files.commit();
  std::printf("wrote %s\n", o.output.c_str());
}

}  // namespace

Command add_blur_command(CLI::App& app) {
  auto o = std::make_shared<BlurOptions>();
  CLI::App* sub = app.add_subcommand("blur", "Blur pyramid of an OpenEXR image: writes PREFIX.blur1/2/3.exr");
  sub->add_option("input", o->input, "Input OpenEXR file")->required();
  sub->add_option("output_prefix", o->prefix, "Output prefix (PREFIX.blur1.exr ...)")->required();
  sub->add_option("--sigmas", o->sigmas,
                  "Sigma of each level in texels of that level, a,b,c (each 0.3 to 4; default 1.2,1.2,1.2)");
  sub->add_flag("--fp32", o->fp32,
                "Keep the levels in RGBA32F and write 32-bit float EXR (default: RGBA16F, half EXR)");
  add_device_option(*sub, o->device);
  return {sub, [o] { run_blur(*o); }};
}

Command add_gauss_command(CLI::App& app) {
  auto o = std::make_shared<GaussOptions>();
  CLI::App* sub =
      app.add_subcommand("gauss", "Gaussian blur of an OpenEXR image; write RGBA half EXR (float with --fp32)");
  sub->add_option("input", o->input, "Input OpenEXR file")->required();
  sub->add_option("output", o->output, "Output OpenEXR file (RGBA half; 32-bit float with --fp32)")->required();
  sub->add_option("--sigma", o->config.sigma_px, "Standard deviation in pixels (0.5 to 64)")->required();
  sub->add_option("--method", o->method, "auto, separable, pyramid or dual")
      ->check(CLI::IsMember({"auto", "separable", "pyramid", "dual"}));
  sub->add_option("--max-error", o->config.max_relative_error,
                  "auto/pyramid: bound on the expected relative L2 error over the whole image (1e-4 to 1)");
  sub->add_flag("--linear", o->linear, "separable: pair taps into bilinear sampler fetches (9 taps in 5)");
  sub->add_flag("--fp32", o->fp32,
                "RGBA32F intermediates and output, written as 32-bit float EXR (default: RGBA16F, half EXR)");
  add_device_option(*sub, o->device);
  return {sub, [o] { run_gauss(*o); }};
}

}  // namespace glint::cli
