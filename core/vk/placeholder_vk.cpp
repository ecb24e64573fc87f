// module placeholder (filled in by its issue)
namespace eikon { [[maybe_unused]] static int placeholder_vk = 0; }
