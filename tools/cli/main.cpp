// The glint command. Exit codes: 0 success (and --help); 2 for anything the user can fix (a bad
// flag or value, an unreadable or unwritable file, a device that does not exist or cannot hold the
// image), printed as one line "glint: error: <message>" on stderr; 1 for internal failures (a
// Vulkan error, an unexpected exception), printed the same way. Never a stack trace.
#include <ImfThreading.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <string>
#include <thread>
#include <vector>

#include "cli/commands.h"

namespace {

int print_error(const std::string& message, int code) {
  std::string line = message;
  std::replace(line.begin(), line.end(), '\n', ' ');
  std::fprintf(stderr, "glint: error: %s\n", line.c_str());
  return code;
}

int exit_code_for(glint::ErrorCode code) {
  switch (code) {
    case glint::ErrorCode::invalid_argument:
    case glint::ErrorCode::io_failure:
    case glint::ErrorCode::no_device:
    case glint::ErrorCode::unsupported_size:
      return 2;
    default:
      return 1;  // vulkan_failure, and formats or usages the CLI itself chose
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"glint: Vulkan compute kernels for HDR post-processing", "glint"};
  app.option_defaults()->always_capture_default();  // --help shows each option's default
  app.set_version_flag("--version", std::to_string(glint::kVersionMajor) + "." + std::to_string(glint::kVersionMinor) +
                                        "." + std::to_string(glint::kVersionPatch));
  app.require_subcommand(0, 1);  // none is reported below, so that "glint typo" says "typo"
  app.footer("Exit status: 0 ok, 2 bad input (flags, files, device choice), 1 internal failure.");
  std::vector<glint::cli::Command> commands = {
      glint::cli::add_devices_command(app), glint::cli::add_bloom_command(app), glint::cli::add_demo_command(app),
      glint::cli::add_lod_command(app),     glint::cli::add_blur_command(app),  glint::cli::add_gauss_command(app),
      glint::cli::add_flare_command(app),   glint::cli::add_cull_command(app),
  };

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);  // --help, --version
    return print_error(std::string(e.what()) + " (see glint --help)", 2);
  }
  if (app.get_subcommands().empty())
    return print_error(
        "a subcommand is required: devices, bloom, demo, lod, blur, gauss, flare or cull (see glint --help)", 2);

  try {
    // OpenEXR compresses and decompresses in parallel when given threads (a 1080p demo writes two).
    Imf::setGlobalThreadCount(static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
    for (const auto& command : commands) {
      if (command.app->parsed()) command.run();
    }
    return 0;
  } catch (const glint::Error& e) {
    return print_error(e.what(), exit_code_for(e.code()));
  } catch (const std::exception& e) {
    return print_error(std::string("internal error: ") + e.what(), 1);
  } catch (...) {
    return print_error("internal error: unknown exception", 1);
  }
}
