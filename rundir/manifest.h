#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "common/pose2.h"

namespace mjslam::rundir {

/// Reads a JSON file (std::runtime_error naming it when unreadable or not
/// JSON); a missing file gives `fallback`.
nlohmann::json ReadJsonFile(const std::string& path, const nlohmann::json& fallback);

/// The manifest.json of a run directory `dir`; throws std::runtime_error
/// naming it when it is missing or not JSON.
nlohmann::json ReadManifest(const std::string& dir);

/// The laser mount X_RS recorded in the manifest at `manifest_path`
/// (`laser_mount` {x, y, th}); none when the file is missing or has no mount.
/// Throws std::runtime_error naming the file when it cannot be read or is not
/// JSON.
std::optional<Pose2> ReadLaserMount(const std::string& manifest_path);

/// The manifest.json of a run directory as a command writes it: at the start
/// with status "running", again as fields are added, and at the end with the
/// outcome. Every write is atomic (docs/run_directory.md lists the keys);
/// when an atomic write fails (a full disk has no room for the new copy),
/// the file is overwritten in place, so that the outcome is still recorded.
class ManifestWriter {
 public:
  /// Writes `fields` plus start_time (now, UTC) and status "running" into
  /// `dir`/manifest.json. Throws std::runtime_error naming the file.
  ManifestWriter(std::string dir, nlohmann::json fields);

  /// The fields, to add or change some before the next Write().
  nlohmann::json& fields() { return manifest_; }
  /// Records the laser mount X_RS (`laser_mount` {x, y, th}); not written yet.
  void SetLaserMount(const Pose2& X_RS);
  /// Writes the fields as they are now.
  void Write() const;
  /// Sets status, end_time (now) and writes: "completed" or "interrupted".
  void Finish(const std::string& status);
  /// Sets status "failed", `error`, end_time (now) and writes. When even
  /// that write fails, throws std::runtime_error whose message is `error`
  /// first (the file that failed) and then why the manifest could not say so.
  void Fail(const std::string& error);

 private:
  std::string path_;
  nlohmann::json manifest_;
};

}  // namespace mjslam::rundir
