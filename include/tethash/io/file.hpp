#pragma once
/// \file io/file.hpp
/// The file handling every format shares: the extension of a path, reading a whole file, and
/// writing files atomically (to a temporary name in the target folder, renamed when complete, so a
/// failed write never leaves half a file where a good one was).
#include "tethash/error.hpp"

#include <functional>
#include <string>
#include <vector>

namespace tethash::io {

/// Lower-case extension with the dot (".vtu"), "" if none.
std::string extension_of(const std::string& path);

/// The bytes of the file at `path`. Throws Error "PATH: is a directory, expected a file",
/// "PATH: cannot open for reading" or "PATH: read error".
std::string read_file(const std::string& path);

/// Writes a file through a temporary name next to it; `write` gets the temporary path.
/// On success renames over `path`; on any exception removes the temporary and rethrows (an Error
/// or WriteError that names the temporary is rethrown naming `path` instead). Throws Error before
/// calling `write` when `path` is a directory or its folder is missing or not a folder; WriteError
/// when the file system refuses the file (creating, writing or renaming it).
void write_atomically(const std::string& path, const std::function<void(const std::string& tmp_path)>& write);
/// The same for files that belong together (TetGen .node + .ele): every file is written to its
/// temporary first; only when all are complete are they renamed into place.
void write_atomically(const std::vector<std::string>& paths,
                      const std::function<void(const std::vector<std::string>& tmp_paths)>& write);
/// Removes every temporary file that write_atomically is writing at this moment. Async-signal-safe:
/// for the handler of SIGINT/SIGTERM in a program, so that an interrupted write leaves nothing behind.
void remove_temporaries_now() noexcept;

/// Writes `text` to `path` through write_atomically, checking every write (WriteError naming `path`).
void write_text_file(const std::string& path, const std::string& text);
/// Writes `texts[i]` to `paths[i]` through write_atomically: all files or none.
void write_text_files(const std::vector<std::string>& paths, const std::vector<std::string>& texts);

/// Checks, before any work, that a file can be created at `path`: not a directory, its folder
/// exists and accepts new files. Throws Error naming `what` (e.g. "--contacts") and the path, or
/// WriteError when the folder refuses new files.
void check_output_file(const std::string& path, const std::string& what = "output");

} // namespace tethash::io
