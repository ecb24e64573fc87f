#include "core/io/build_id.h"

#include <elf.h>
#include <link.h>

#include <cstdint>
#include <cstring>

namespace eikon {
namespace {

struct Search {
  uintptr_t address = 0;  // an address inside the object whose id is wanted
  std::string id;
};

/// The NT_GNU_BUILD_ID note in the PT_NOTE segments of a loaded object, as hex.
std::string buildIdOf(const dl_phdr_info* info) {
  for (int p = 0; p < info->dlpi_phnum; ++p) {
    const ElfW(Phdr)& ph = info->dlpi_phdr[p];
    if (ph.p_type != PT_NOTE) continue;
    const auto* at = reinterpret_cast<const unsigned char*>(info->dlpi_addr + ph.p_vaddr);
    size_t left = ph.p_memsz;
    while (left >= sizeof(ElfW(Nhdr))) {
      ElfW(Nhdr) note;
      std::memcpy(&note, at, sizeof note);
      const size_t name_size = (note.n_namesz + 3u) & ~size_t(3);
      const size_t desc_size = (note.n_descsz + 3u) & ~size_t(3);
      const size_t total = sizeof note + name_size + desc_size;
      if (total > left) break;
      const auto* name = at + sizeof note;
      if (note.n_type == NT_GNU_BUILD_ID && note.n_namesz == 4 &&
          std::memcmp(name, "GNU", 4) == 0) {
        static const char digits[] = "0123456789abcdef";
        std::string hex;
        for (size_t i = 0; i < note.n_descsz; ++i) {
          const unsigned char b = name[name_size + i];
          hex += digits[b >> 4];
          hex += digits[b & 15];
        }
        return hex;
      }
      at += total;
      left -= total;
    }
  }
  return {};
}

int visit(dl_phdr_info* info, size_t, void* data) {
  auto* s = static_cast<Search*>(data);
  for (int p = 0; p < info->dlpi_phnum; ++p) {
    const ElfW(Phdr)& ph = info->dlpi_phdr[p];
    if (ph.p_type != PT_LOAD) continue;
    const uintptr_t lo = info->dlpi_addr + ph.p_vaddr;
    if (s->address >= lo && s->address < lo + ph.p_memsz) {
      s->id = buildIdOf(info);
      return 1;  // found the object that holds this code
    }
  }
  return 0;
}

}  // namespace

std::string codeBuildId() {
  static const std::string id = [] {
    Search s;
    s.address = reinterpret_cast<uintptr_t>(&codeBuildId);
    dl_iterate_phdr(visit, &s);
    return s.id;
  }();
  return id;
}

}  // namespace eikon
