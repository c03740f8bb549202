// Atomic replacement of output files for the glint command (and anything else that must never
// leave a truncated or half-written file behind).
//
// Each output is written to a temporary file in the target's own directory (so that rename(2) is
// an atomic replacement within one filesystem, POSIX.1-2017 rename()), flushed to disk with
// fsync(2), and renamed over the target only when every output of the command has been written:
// a reader sees either all the previous files or all the new ones, never a mix, and never a
// truncated file. On failure (an exception, a full disk, a file-size limit) the temporaries are
// removed and the previous files are left untouched. SIGTERM, SIGINT and SIGHUP are caught while
// temporaries exist: the handler removes them (unlink(2) is async-signal-safe) and the process
// then dies of the same signal. SIGXFSZ is ignored, so that a file-size limit makes the write fail
// with EFBIG (an Error) instead of killing the process with the temporary in place.
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace glint::io {

/// The outputs of one command, replaced together.
///
///   AtomicOutputs out;
///   out.write("a.exr", [&](const std::string& tmp) { write_exr_half(tmp, image); });
///   out.write("a.png", [&](const std::string& tmp) { write_png_tonemapped(tmp, image); });
///   out.commit();  // both renamed over a.exr and a.png; before this, neither was touched
///
/// Destroying the object without commit() (an exception on the way) removes the temporaries.
class AtomicOutputs {
 public:
  AtomicOutputs();
  ~AtomicOutputs();
  AtomicOutputs(const AtomicOutputs&) = delete;
  AtomicOutputs& operator=(const AtomicOutputs&) = delete;

  /// Creates a temporary file next to `target` (".NAME.PID.N.glint-tmp" in the same directory,
  /// with the target's permissions when it exists, else 0666 less the umask), calls
  /// `writer(temporary)`, which must write the whole file there, then fsyncs it. Throws
  /// Error(io_failure) naming `target` when the directory is missing, when the writer throws (its
  /// message names the target instead of the temporary), or when the data cannot be flushed; the
  /// temporary is then already removed. `target` must differ from every earlier target.
  void write(const std::string& target, const std::function<void(const std::string& temporary)>& writer);

  /// Renames every temporary over its target (in the order written), then fsyncs each directory.
  /// A SIGTERM/SIGINT/SIGHUP that arrives during the renames is held until they are all done.
  /// Throws Error(io_failure) when a rename fails (the remaining temporaries are removed).
  void commit();

  /// The targets written so far, in order.
  std::vector<std::string> targets() const;

 private:
  struct Entry {
    std::string target;
    std::string temporary;
    int slot = -1;  // index in the signal handler's table of temporaries
  };
  std::vector<Entry> entries_;
  bool committed_ = false;
};

/// Writes `text` to `path` (replacing it in place; use AtomicOutputs for an atomic replacement).
/// Throws Error(io_failure) naming the path when it cannot be opened or written completely.
void write_text_file(const std::string& path, std::string_view text);

/// The suffix of every temporary AtomicOutputs makes (".glint-tmp"), for tests that look for
/// leftovers.
inline constexpr const char* kTemporarySuffix = ".glint-tmp";

}  // namespace glint::io
