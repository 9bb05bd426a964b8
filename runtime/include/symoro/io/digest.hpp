// Content digests: XXH3-128 (xxHash, Debian libxxhash-dev) of bytes, as 32 hex digits. They
// detect change (a saved run whose log was edited, a parameters file edited after identify wrote
// it, a robot folder edited after it was compiled); they are no signature against a deliberate
// forger. XXH3 hashes at memory speed: a study's logs cost their reading time.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace symoro::io {

std::string digest_of(std::string_view bytes);

// The digest of a file's bytes, read in blocks (a log of gigabytes needs no memory for it).
// Throws DataError naming the file when it cannot be read.
std::string file_digest(const std::filesystem::path& file);

}  // namespace symoro::io
