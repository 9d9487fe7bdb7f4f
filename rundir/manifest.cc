#include "rundir/manifest.h"

#include <exception>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <utility>

#include "rundir/layout.h"
#include "rundir/run_files.h"

namespace mjslam::rundir {

nlohmann::json ReadJsonFile(const std::string& path, const nlohmann::json& fallback) {
  if (!std::filesystem::exists(path)) return fallback;
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot be read");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& error) {
    throw std::runtime_error(path + ": not valid JSON: " + error.what());
  }
}

nlohmann::json ReadManifest(const std::string& dir) {
  const std::string path = PathIn(dir, kManifestFile);
  const nlohmann::json manifest = ReadJsonFile(path, nullptr);
  if (manifest.is_null()) throw std::runtime_error(path + ": missing");
  return manifest;
}

std::optional<Pose2> ReadLaserMount(const std::string& manifest_path) {
  const nlohmann::json manifest = ReadJsonFile(manifest_path, nullptr);
  if (!manifest.is_object() || !manifest.contains("laser_mount")) return std::nullopt;
  const nlohmann::json& mount = manifest["laser_mount"];
  return Pose2(mount.at("x").get<double>(), mount.at("y").get<double>(),
               mount.at("th").get<double>());
}

ManifestWriter::ManifestWriter(std::string dir, nlohmann::json fields)
    : path_(PathIn(dir, kManifestFile)), manifest_(std::move(fields)) {
  manifest_["start_time"] = UtcNow();
  manifest_["status"] = "running";
  Write();
}

void ManifestWriter::SetLaserMount(const Pose2& X_RS) {
  manifest_["laser_mount"] = {{"x", X_RS.x}, {"y", X_RS.y}, {"th", X_RS.theta}};
}

void ManifestWriter::Write() const {
  std::exception_ptr atomic_error;
  try {
    WriteJsonAtomically(path_, manifest_);
    return;
  } catch (const std::exception&) {
    atomic_error = std::current_exception();
  }
  // No room for a second copy: reuse the old file's blocks, or report the
  // first failure (whole: a copy would slice it to std::exception).
  try {
    OverwriteFile(path_, JsonText(manifest_));
  } catch (const std::exception&) {
    std::rethrow_exception(atomic_error);
  }
}

void ManifestWriter::Finish(const std::string& status) {
  manifest_["status"] = status;
  manifest_["end_time"] = UtcNow();
  Write();
}

void ManifestWriter::Fail(const std::string& error) {
  manifest_["status"] = "failed";
  manifest_["error"] = error;
  manifest_["end_time"] = UtcNow();
  try {
    Write();
  } catch (const std::exception& manifest_error) {
    throw std::runtime_error(error + " (" + manifest_error.what() + ")");
  }
}

}  // namespace mjslam::rundir
