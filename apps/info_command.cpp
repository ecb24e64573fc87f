// eikon info: the Vulkan device eikon would use, its limits, and the build.
#include <cstdio>

#include "apps/commands.h"
#include "core/vk/context.h"

namespace eikon::cli {

void addInfoCommand(CLI::App& app) {
  auto* sub = app.add_subcommand("info", "Show the Vulkan device, its limits and the build");
  sub->callback([] {
    auto ctx = vk::Context::create();
    const auto& l = ctx->limits();
    std::printf("eikon 0.1.0 (C++20, %s build)\n",
#ifdef NDEBUG
                "release"
#else
                "debug"
#endif
    );
    std::printf("device:            %s (%s), Vulkan %s\n", ctx->deviceName().c_str(), ctx->deviceTypeName().c_str(),
                ctx->apiVersionString().c_str());
    std::printf("max 3D image side: %u voxels\n", l.max_image_dimension_3d);
    std::printf("max storage buffer:%llu MiB\n", (unsigned long long)(l.max_storage_buffer_range >> 20));
    std::printf("device heap:       %llu MiB\n", (unsigned long long)(l.heap_size >> 20));
    std::printf("shader float64:    %s\n", l.shader_float64 ? "yes" : "no");
    std::printf("validation layers: %s (EIKON_VALIDATION=1 enables)\n", ctx->validationEnabled() ? "on" : "off");
  });
}

}  // namespace eikon::cli
