#include "core/output_folder.h"

#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <nlohmann/json.hpp>

#include "core/checkpoint.h"
#include "core/error.h"

namespace femto {

namespace fs = std::filesystem;

namespace {
const char* kStagingTag = ".femto-tmp.";
const char* kOldTag = ".femto-old.";

bool is_checkpoint_name(const std::string& name) {
  return name == "checkpoint.bin" || name.rfind("checkpoint.bin.tmp.", 0) == 0;
}

// A staging or old folder of a process that no longer exists.
bool stale(const std::string& name, const std::string& prefix) {
  if (name.rfind(prefix, 0) != 0) return false;
  const std::string pid = name.substr(prefix.size());
  if (pid.empty() || pid.find_first_not_of("0123456789") != std::string::npos || pid.size() > 9) return false;
  const pid_t p = static_cast<pid_t>(std::stol(pid));
  return p != ::getpid() && ::kill(p, 0) != 0 && errno == ESRCH;
}
}  // namespace

std::string foreign_entry(const std::string& dir, bool& is_femto) {
  is_femto = false;
  std::set<std::string> listed;
  bool frames_listed = false;
  const fs::path json_path = fs::path(dir) / "render.json";
  std::error_code ec;
  if (fs::is_regular_file(json_path, ec)) {
    std::ifstream in(json_path, std::ios::binary);
    const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
    if (j.is_object() && j.contains("femto_version")) {
      is_femto = true;
      listed.insert("render.json");
      if (j.contains("outputs") && j["outputs"].is_array())
        for (const auto& f : j["outputs"])
          if (f.is_string()) listed.insert(f.get<std::string>());
      if (j.contains("files") && j["files"].is_array())
        for (const auto& f : j["files"])
          if (f.is_object() && f.contains("name") && f["name"].is_string()) listed.insert(f["name"].get<std::string>());
      frames_listed = listed.count("frames/") > 0;
    }
  }
  std::string foreign;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (is_checkpoint_name(name)) {
      if (name == "checkpoint.bin" && looks_like_checkpoint(it->path().string())) is_femto = true;
      continue;
    }
    if (name == "frames" && it->is_directory()) {
      if (frames_listed) continue;
      bool all = true;  // every frame listed one by one
      for (fs::directory_iterator f(it->path(), ec), e; !ec && f != e; f.increment(ec))
        if (!listed.count("frames/" + f->path().filename().string())) {
          if (foreign.empty()) foreign = "frames/" + f->path().filename().string();
          all = false;
          break;
        }
      if (all) continue;
      break;
    }
    if (!listed.count(name)) {
      foreign = name;
      break;
    }
  }
  return foreign;
}

OutputFolder::OutputFolder(const std::string& dir, bool checkpoints) : dir_(dir) {
  while (dir_.size() > 1 && dir_.back() == '/') dir_.pop_back();
  const fs::path p(dir_);
  const std::string where = "--out " + clip(dir_, 200);
  std::error_code ec;
  const fs::file_status status = fs::status(p, ec);
  const bool exists = fs::exists(status);
  if (exists && !fs::is_directory(status)) throw InputError(where + ": exists and is not a folder");
  if (exists) {
    bool is_femto = false;
    const std::string foreign = foreign_entry(dir_, is_femto);
    if (!foreign.empty())
      throw InputError(where + ": the folder holds '" + clip(foreign) + "', which is not part of a femto render " +
                       (is_femto ? "there" : "(no render.json written by femto)") +
                       "; femto replaces the whole folder, so give an empty or new folder, or move the file away");
    if (::access(dir_.c_str(), W_OK) != 0)
      throw InputError(where + ": cannot write to the folder: " + std::strerror(errno));
  }
  fs::path parent = p.parent_path();
  if (parent.empty()) parent = ".";
  const std::string name = p.filename().string();
  if (name.empty() || name == "." || name == "..")
    throw InputError(where + ": give a folder name (femto replaces the folder as a whole)");
  // Leftovers of runs that were killed (kill -9, power loss) are removed.
  for (fs::directory_iterator it(parent, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string n = it->path().filename().string();
    if (stale(n, "." + name + kStagingTag) || stale(n, "." + name + kOldTag)) {
      std::error_code rm;
      fs::remove_all(it->path(), rm);
    }
  }
  staging_ = (parent / ("." + name + kStagingTag + std::to_string(::getpid()))).string();
  fs::remove_all(staging_, ec);
  if (!fs::create_directories(parent, ec) && ec)
    throw InputError(where + ": cannot create the parent folder: " + ec.message());
  if (!fs::create_directory(staging_, ec) || ec)
    throw InputError(where + ": cannot write beside the folder (" + clip(parent.string(), 120) +
                     "): " + (ec ? ec.message() : std::string("exists")));
  if (checkpoints && !exists) {
    if (!fs::create_directory(p, ec) || ec) {
      fs::remove_all(staging_, ec);
      throw InputError(where + ": cannot create the folder: " + ec.message());
    }
    created_dir_ = true;
  }
}

OutputFolder::~OutputFolder() {
  if (!committed_) discard();
}

void OutputFolder::commit() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::error_code ec;
  const fs::path old = fs::path(staging_).parent_path() /
                       ("." + fs::path(dir_).filename().string() + kOldTag + std::to_string(::getpid()));
  if (fs::exists(dir_, ec)) {
    if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, dir_.c_str(), RENAME_EXCHANGE) == 0) {
      committed_ = true;
      fs::remove_all(staging_, ec);  // now the previous folder
      return;
    }
    // No atomic exchange on this filesystem: move the old folder aside first.
    if (std::rename(dir_.c_str(), old.c_str()) != 0)
      throw RuntimeError(dir_ + ": cannot replace the output folder: " + std::strerror(errno));
  }
  if (std::rename(staging_.c_str(), dir_.c_str()) != 0) {
    const int err = errno;
    std::rename(old.c_str(), dir_.c_str());
    throw RuntimeError(dir_ + ": cannot move the outputs into place: " + std::strerror(err));
  }
  committed_ = true;
  fs::remove_all(old, ec);
}

void OutputFolder::discard() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (committed_) return;
  std::error_code ec;
  // Other threads may still be writing into the staging folder: remove until it is gone (files
  // cannot be created in it once it no longer exists; nothing recreates it).
  for (int i = 0; i < 100 && fs::exists(staging_, ec); ++i) fs::remove_all(staging_, ec);
  const std::string tmp = checkpoint_path() + ".tmp." + std::to_string(::getpid());
  fs::remove(tmp, ec);
  if (created_dir_) fs::remove(dir_, ec);  // only when still empty
}

}  // namespace femto
