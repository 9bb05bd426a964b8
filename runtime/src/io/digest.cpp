#include "symoro/io/digest.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include <fmt/format.h>

#define XXH_INLINE_ALL  // header-only: no library to link
#include <xxhash.h>

#include "symoro/error.hpp"

namespace symoro::io {

namespace {
std::string hex(const XXH128_hash_t& h) { return fmt::format("{:016x}{:016x}", h.high64, h.low64); }
}  // namespace

std::string digest_of(std::string_view bytes) { return hex(XXH3_128bits(bytes.data(), bytes.size())); }

std::string file_digest(const std::filesystem::path& file) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(file.c_str(), "rb"), &std::fclose);
  if (!f) throw DataError(file.string(), 0, fmt::format("cannot read: {}", std::strerror(errno)));
  std::unique_ptr<XXH3_state_t, XXH_errorcode (*)(XXH3_state_t*)> state(XXH3_createState(), &XXH3_freeState);
  XXH3_128bits_reset(state.get());
  std::vector<char> block(1 << 20);
  std::size_t n;
  while ((n = std::fread(block.data(), 1, block.size(), f.get())) > 0)
    XXH3_128bits_update(state.get(), block.data(), n);
  if (std::ferror(f.get())) throw DataError(file.string(), 0, fmt::format("read failed: {}", std::strerror(errno)));
  return hex(XXH3_128bits_digest(state.get()));
}

}  // namespace symoro::io
