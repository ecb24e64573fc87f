// eikon info: the Vulkan device eikon would use, its limits, and the build.
#include <cstdio>
#include <string>

#include "apps/commands.h"
#include "core/scene/material_library.h"
#include "core/scene/scene.h"
#include "core/session/front_end.h"
#include "core/session/session.h"

namespace eikon::cli {

void addInfoCommand(CLI::App& app) {
  auto* sub = app.add_subcommand(
      "info", "Show the Vulkan device, its limits, the build and the material library");
  sub->callback([] {
    const DeviceInfo d = deviceInfo(*newContext());
    std::printf("eikon 0.1.0 (C++20, %s build)\n",
#ifdef NDEBUG
                "release"
#else
                "debug"
#endif
    );
    // One column for every value: the labels are padded to the longest ("max storage buffer:").
    auto row = [](const char* label, const std::string& value) {
      std::printf("%-20s%s\n", (std::string(label) + ":").c_str(), value.c_str());
    };
    row("device", d.name + " (" + d.type + "), Vulkan " + d.api_version);
    row("max 3D image side", std::to_string(d.max_image_dimension_3d) + " voxels");
    row("max storage buffer", std::to_string(d.max_storage_buffer_range >> 20) + " MiB");
    row("device heap", std::to_string(d.heap_size >> 20) + " MiB");
    row("shader float64", d.shader_float64 ? "yes" : "no");
    row("validation layers",
        std::string(d.validation ? "on" : "off") + " (EIKON_VALIDATION=1 enables)");
    // The library a scene's "material" names (docs/scene-format.md "materials").
    std::string names, folders;
    for (const std::string& n : libraryMaterialNames()) names += (names.empty() ? "" : ", ") + n;
    for (const auto& dir : materialSearchPath())
      folders += (folders.empty() ? "" : ":") + dir.string();
    row("materials",
        printable((names.empty() ? std::string("none") : names) + " (" + folders + ")"));
  });
}

}  // namespace eikon::cli
