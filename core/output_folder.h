#pragma once
// The output folder of a render, replaced as a whole: outputs are written into a staging folder
// beside it (".NAME.femto-tmp.PID"), which is swapped in at the end, so the folder always holds
// exactly one render's files, old and new never mix, and a stopped or failed run leaves the
// previous folder as it was.
#include <mutex>
#include <string>

namespace femto {

class OutputFolder {
 public:
  /// Checks `dir` before anything is rendered and creates the staging folder. Throws InputError
  /// when `dir` exists but is not a folder, holds files that are not part of a femto render
  /// (anything but the files its render.json lists and checkpoint.bin) unless it is empty, or
  /// cannot be written. Removes staging folders left beside it by runs that no longer exist.
  /// With `checkpoints`, `dir` itself is created (if missing) to hold checkpoint.bin.
  OutputFolder(const std::string& dir, bool checkpoints);
  /// Removes the staging folder unless committed (a failed run leaves `dir` unchanged).
  ~OutputFolder();
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

  const std::string& dir() const { return dir_; }
  const std::string& staging() const { return staging_; }
  std::string checkpoint_path() const { return dir_ + "/checkpoint.bin"; }

  /// Replaces `dir` by the staging folder (an atomic exchange where the filesystem supports it).
  void commit();
  /// Removes what this run created and did not commit (staging folder, temporary checkpoint,
  /// `dir` if this run created it and it is still empty). Safe to call from the signal thread.
  void discard();
  /// Held while committing and while writing checkpoints: discard() waits for it, so an abort
  /// never interrupts a swap or leaves a half-written checkpoint name behind.
  std::mutex& mutex() { return mutex_; }

 private:
  std::string dir_, staging_;
  bool created_dir_ = false, committed_ = false;
  std::mutex mutex_;
};

/// Names in `dir` that are not part of a femto render there; empty when `dir` is a femto render
/// folder (its render.json has "femto_version"), holds only checkpoint files, or is empty.
/// `is_femto` tells whether a femto render.json or checkpoint was found.
std::string foreign_entry(const std::string& dir, bool& is_femto);

}  // namespace femto
