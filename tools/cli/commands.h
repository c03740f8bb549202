// The glint command: one file per subcommand (devices_command.cpp, bloom_command.cpp, ...), each
// registering its options on the CLI11 app and returning what to run once parsing succeeded.
// Adding an effect adds one <effect>_command.cpp and one line in main.cpp.
#pragma once

#include <glint/flare.h>
#include <glint/glint.h>

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

#include "core/cpu_image.h"
#include "io/exr_io.h"

namespace glint::cli {

/// A registered subcommand. `run` is called only if `app` was the subcommand given; it reports
/// failures by throwing (glint::Error for anything the user can fix).
struct Command {
  CLI::App* app = nullptr;
  std::function<void()> run;
};

Command add_devices_command(CLI::App& app);
Command add_bloom_command(CLI::App& app);
Command add_demo_command(CLI::App& app);
Command add_lod_command(CLI::App& app);
Command add_blur_command(CLI::App& app);
Command add_gauss_command(CLI::App& app);
Command add_flare_command(CLI::App& app);
Command add_cull_command(CLI::App& app);

// ---- helpers shared by the commands (common.cpp) ----

/// A depth OpenEXR file as `glint flare --depth` and `glint cull --depth` read it: channel Z, else
/// the first channel; every value finite and in [0, 1]. Throws Error(invalid_argument) naming the
/// pixel and value, Error(io_failure) when unreadable.
io::ExrChannel read_depth_exr(const std::string& path);

/// "discrete GPU", "CPU", ...
const char* device_type_name(VkPhysicalDeviceType type);

/// Parses "WIDTHxHEIGHT" (each 1 to 16384). Throws Error(invalid_argument) naming `option`.
VkExtent2D parse_size(const std::string& option, const std::string& text);

/// Throws Error(invalid_argument) unless --exposure is finite and > 0.
void check_exposure(float exposure);

/// Throws Error(io_failure) when `path` cannot be an output file: its directory is missing or it
/// is a directory. Checked before GPU work so that a typo does not cost a run.
void check_output_path(const std::string& path);

/// Throws Error(invalid_argument) when two of the named output paths are the same file (after
/// resolving "." and ".." and symbolic links of the existing part), e.g. `flare OUT --stats OUT`.
/// options[i] names paths[i] in the message.
void check_distinct_outputs(const std::vector<std::string>& options, const std::vector<std::string>& paths);

/// The lens-flare looks by name, any case: retro_subtle, retro_intense, cinematic, disabled, or
/// default (FlareConfig{}: ratio 2, intensity 1). The one parser of --preset for `demo` and `flare`.
/// Throws Error(invalid_argument) naming --preset and the accepted names.
FlareConfig flare_preset_from_name(const std::string& name);

/// --help text of --preset.
inline constexpr const char* kFlarePresetHelp =
    "Lens-flare look: retro_subtle, retro_intense, cinematic, disabled, or default (ratio 2, intensity 1); any case";

/// Adds --device to a subcommand (an index or a name substring, as ContextOptions::device).
void add_device_option(CLI::App& sub, std::string& device);

/// Prints each profiler stage and the total in ms, or a note when the device has no timestamps.
void print_stages(const Profiler& profiler);

/// The context a command runs on: standalone, on --device (empty: the default choice).
Context make_context(const std::string& device);

/// Prints "device: NAME (TYPE)" and "input: PATH, WxH".
void print_device(const Context& context, const std::string& input_path, const CpuImage& input);

/// Makes and frees the device images run_image_effect() will make for an input of `extent`, so
/// that an input too large for the device is refused (Error(unsupported_size), naming the bytes
/// needed and available) before the file's pixels are read.
void check_device_images(const Context& context, VkExtent2D extent, VkFormat output_format);

/// Uploads `input` as RGBA32F and, in one submission, records `effect` after the profiler's
/// reset and "start" mark. The effect gets the input image and a profiler to mark.
void run_on_input(const Context& context, const CpuImage& input, Profiler& profiler,
                  const std::function<void(VkCommandBuffer, Image& source, Profiler*)>& effect);

/// run_on_input() with an output image of the same size in `output_format` (RGBA16F, or RGBA32F
/// for --fp32), which is read back and returned.
CpuImage run_image_effect(const Context& context, const CpuImage& input, Profiler& profiler,
                          const std::function<void(VkCommandBuffer, Image& source, Image& result, Profiler*)>& effect,
                          VkFormat output_format = VK_FORMAT_R16G16B16A16_SFLOAT);

/// Writes an effect's result at the precision it was computed in: RGBA32F as 32-bit float EXR
/// channels (--fp32), anything else as half.
void write_result_exr(const std::string& path, const CpuImage& image, bool fp32);

}  // namespace glint::cli
