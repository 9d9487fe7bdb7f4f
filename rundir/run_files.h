#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace mjslam::rundir {

/// Writes `value` to `path` through a temporary file in the same folder and a
/// rename, so readers see either the old file or the whole new one. Throws
/// std::runtime_error naming the file on failure.
void WriteFileAtomically(const std::string& path, const std::string& contents);

/// Pretty-printed JSON, written atomically.
void WriteJsonAtomically(const std::string& path, const nlohmann::json& value);

/// The whole text of a file; empty when it cannot be read.
std::string ReadTextFile(const std::string& path);

/// Content hash of a file: "fnv1a64:<16 hex digits>". Throws if unreadable.
std::string HashFile(const std::string& path);

/// Current UTC time as ISO 8601 ("2026-11-23T09:00:00Z").
std::string UtcNow();

/// Creates `dir` (and parents). Throws std::runtime_error naming it if it
/// cannot, or if it exists and is not a folder.
void MakeRunDirectory(const std::string& dir);

}  // namespace mjslam::rundir
