// glint devices: the Vulkan devices this machine offers, in the order --device indexes them.
#include <cstdio>

#include "cli/commands.h"

namespace glint::cli {

Command add_devices_command(CLI::App& app) {
  CLI::App* sub = app.add_subcommand("devices", "List the Vulkan devices (index, name, type, Vulkan version)");
  return {sub, [] {
            const auto devices = list_devices();
            if (devices.empty()) throw Error(ErrorCode::no_device, "no Vulkan device found (is a driver installed?)");
            std::printf("%-6s %-15s %-8s %s\n", "index", "type", "vulkan", "name");
            for (const auto& d : devices) {
              char version[32];
              std::snprintf(version, sizeof version, "%u.%u.%u", VK_API_VERSION_MAJOR(d.api_version),
                            VK_API_VERSION_MINOR(d.api_version), VK_API_VERSION_PATCH(d.api_version));
              std::printf("%-6u %-15s %-8s %s\n", d.index, device_type_name(d.type), version, d.name.c_str());
            }
          }};
}

}  // namespace glint::cli
