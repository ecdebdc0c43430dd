#pragma once
// Files read only when they are files, and written so that a reader never sees half of one: the
// content goes to a temporary next to the target, is flushed to disk, and is renamed into place
// (atomic on POSIX filesystems).

#include <filesystem>
#include <string_view>

#include <strata/core/result.hpp>

namespace strata {

/// Fails unless `path` names a regular file (a link to one counts), without opening it: "no such
/// file", "is a directory, not <what>", or "is not a regular file (a FIFO, socket or device)".
/// Every input a user names goes through it before it is opened, so that a FIFO or a device
/// never blocks a read (opening a FIFO waits for a writer) nor streams without end.
Status requireRegularFile(const std::filesystem::path& path, std::string_view what);

/// A temporary path next to `target` ("<name>.tmp-<pid>-<n>"), on the same filesystem.
std::filesystem::path temporaryPathFor(const std::filesystem::path& target);

/// Whether the file name `name` is one temporaryPathFor() makes for the file name `file`
/// (`file.tmp-PID-N`): what a clean-up may remove, and nothing a user named alike.
bool isTemporaryNameOf(std::string_view name, std::string_view file);

/// fsyncs `temporary` and renames it onto `target`; on failure removes the temporary.
Status commitTemporary(const std::filesystem::path& temporary, const std::filesystem::path& target);

/// Writes `content` to `target` atomically.
Status writeFileAtomic(const std::filesystem::path& target, std::string_view content);

}  // namespace strata
