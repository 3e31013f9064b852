// File helpers for run directories: atomic writes and reads with user-facing errors.
//
// Every file a run leaves behind is written atomically: the contents go to a temporary
// file in the same directory, are flushed to disk, and the temporary is renamed over
// the target, and the directory is flushed after the rename. rename(2) is atomic within a
// file system, so a kill at any moment leaves either the old file or the new one, never
// a torn one; a write that fails (a full disk: ENOSPC) removes its temporary and leaves
// the old file as it was.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace diverse {

// Writes `contents` to `path` atomically (temp file + fsync + rename + fsync of the
// directory). Creates missing
// parent directories. Throws UserError naming the path if it cannot be written.
void write_file_atomic(const std::filesystem::path& path, const std::string& contents);

// Pretty-printed JSON (2-space indent), written atomically. Doubles are printed with
// the shortest representation that parses back to the same bits.
void write_json_atomic(const std::filesystem::path& path, const nlohmann::json& value);

// Reads a whole file; throws UserError "PATH: cannot read (reason)" if it cannot.
std::string read_file(const std::filesystem::path& path);

// Parses a JSON file; throws UserError "PATH: not valid JSON (detail)".
nlohmann::json read_json(const std::filesystem::path& path);

// Removes the temporaries of atomic writes in `dir` (not below it) that a process killed
// mid-write left behind: "NAME.tmp.PID.N" whose PID no longer runs. Returns how many.
int remove_stale_temporaries(const std::filesystem::path& dir);

// Makes sure `dir` exists and is writable, creating it if needed; throws UserError
// "DIR: cannot create output directory (reason)" otherwise.
void ensure_writable_directory(const std::filesystem::path& dir);

}  // namespace diverse
