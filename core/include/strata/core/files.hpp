#pragma once
// Files written so that a reader never sees half of one: the content goes to a temporary next
// to the target, is flushed to disk, and is renamed into place (atomic on POSIX filesystems).

#include <filesystem>
#include <string_view>

#include <strata/core/result.hpp>

namespace strata {

/// A temporary path next to `target` ("<name>.tmp-<pid>-<n>"), on the same filesystem.
std::filesystem::path temporaryPathFor(const std::filesystem::path& target);

/// fsyncs `temporary` and renames it onto `target`; on failure removes the temporary.
Status commitTemporary(const std::filesystem::path& temporary, const std::filesystem::path& target);

/// Writes `content` to `target` atomically.
Status writeFileAtomic(const std::filesystem::path& target, std::string_view content);

}  // namespace strata
