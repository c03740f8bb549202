// AtomicOutputs: temporary file, fsync(2), rename(2) (POSIX.1-2017: "If the link named by the new
// argument exists, it shall be removed and old renamed to new. ... a link named new shall remain
// visible to other threads throughout the renaming operation and refer either to the file referred
// to by new or old before the operation began"), then fsync of the directory so that the rename
// itself survives a crash.
//
// The signal handler only reads a fixed table of paths and calls unlink(2), signal(2) and raise(3),
// which are async-signal-safe (POSIX.1-2017, 2.4.3); the table is guarded by lock-free atomics.
#include "io/atomic_outputs.h"

#include <fcntl.h>
#include <glint/glint.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>

namespace glint::io {
namespace {

// ---- the signal handler's table of temporaries ----

constexpr int kSlots = 64;  // temporaries alive at once, process-wide (a command writes at most 6)
constexpr size_t kPathBytes = 4096;

struct Slot {
  std::atomic<int> state{0};  // 0 free, 1 being filled, 2 holds a temporary to remove on a signal
  char path[kPathBytes];
};
Slot g_slots[kSlots];
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler needs lock-free atomics");

// 0: idle; 1: commit() is renaming (a signal is held in g_pending); 2: a signal is removing the
// temporaries and the process is about to die.
std::atomic<int> g_phase{0};
std::atomic<int> g_pending{0};

extern "C" void remove_temporaries_and_die(int sig) {
  int expected = 0;
  if (!g_phase.compare_exchange_strong(expected, 2)) {
    if (expected == 1) g_pending.store(sig);  // commit() re-raises it when the renames are done
    return;                                   // 2: another thread is already doing this
  }
  for (Slot& s : g_slots) {
    if (s.state.load() == 2) ::unlink(s.path);
  }
  ::signal(sig, SIG_DFL);
  ::raise(sig);  // blocked until the handler returns, then the default action: termination
}

void install_handlers_once() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (int sig : {SIGTERM, SIGINT, SIGHUP}) {
      struct sigaction old {};
      if (::sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;  // e.g. nohup
      struct sigaction sa {};
      sa.sa_handler = remove_temporaries_and_die;
      sigemptyset(&sa.sa_mask);
      sa.sa_flags = SA_RESTART;
      ::sigaction(sig, &sa, nullptr);
    }
    // A file-size limit (ulimit -f) then fails the write with EFBIG instead of killing us.
    ::signal(SIGXFSZ, SIG_IGN);
  });
}

int claim_slot(const std::string& path) {
  if (path.size() + 1 > kPathBytes) {
    throw Error(ErrorCode::io_failure, path + ": path longer than " + std::to_string(kPathBytes - 1) + " bytes");
  }
  for (int i = 0; i < kSlots; ++i) {
    int expected = 0;
    if (g_slots[i].state.compare_exchange_strong(expected, 1)) {
      std::memcpy(g_slots[i].path, path.c_str(), path.size() + 1);
      g_slots[i].state.store(2);
      return i;
    }
  }
  throw Error(ErrorCode::io_failure,
              path + ": more than " + std::to_string(kSlots) + " temporary output files at once");
}

void release_slot(int slot) {
  if (slot >= 0) g_slots[slot].state.store(0);
}

// Holds signals (phase 1) for the lifetime of the object; re-raises one that came meanwhile.
class HoldSignals {
 public:
  HoldSignals() {
    int expected = 0;
    // A signal is already removing the temporaries: the process is about to die; wait for it.
    while (!g_phase.compare_exchange_strong(expected, 1)) {
      expected = 0;
      ::pause();
    }
  }
  ~HoldSignals() {
    g_phase.store(0);
    if (const int sig = g_pending.exchange(0)) ::raise(sig);
  }
  HoldSignals(const HoldSignals&) = delete;
  HoldSignals& operator=(const HoldSignals&) = delete;
};

std::string errno_text(int err) { return std::strerror(err); }

// `message` with every occurrence of `from` replaced by `to`.
std::string replace_all(std::string message, const std::string& from, const std::string& to) {
  if (from.empty()) return message;
  for (size_t at = message.find(from); at != std::string::npos; at = message.find(from, at + to.size())) {
    message.replace(at, from.size(), to);
  }
  return message;
}

void fsync_path(const std::string& path, bool directory) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | (directory ? O_DIRECTORY : 0));
  if (fd < 0) {
    if (directory) return;  // best effort: the files themselves are already on disk
    throw Error(ErrorCode::io_failure, path + ": cannot reopen to flush: " + errno_text(errno));
  }
  const int rc = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  // Directories on some filesystems do not support fsync (EINVAL): nothing more can be done there.
  if (rc != 0 && !(directory && (err == EINVAL || err == EROFS))) {
    throw Error(ErrorCode::io_failure, path + ": cannot flush to disk: " + errno_text(err));
  }
}

std::string directory_of(const std::string& target) {
  const std::filesystem::path p(target);
  return p.has_parent_path() ? p.parent_path().string() : std::string(".");
}

}  // namespace

AtomicOutputs::AtomicOutputs() { install_handlers_once(); }

AtomicOutputs::~AtomicOutputs() {
  for (const Entry& e : entries_) {
    if (!committed_) ::unlink(e.temporary.c_str());
    release_slot(e.slot);
  }
}

std::vector<std::string> AtomicOutputs::targets() const {
  std::vector<std::string> t;
  for (const Entry& e : entries_) t.push_back(e.target);
  return t;
}

void AtomicOutputs::write(const std::string& target, const std::function<void(const std::string& temporary)>& writer) {
  if (committed_) throw Error(ErrorCode::invalid_argument, target + ": AtomicOutputs already committed");
  for (const Entry& e : entries_) {
    if (e.target == target) throw Error(ErrorCode::invalid_argument, target + ": written twice by one command");
  }
  namespace fs = std::filesystem;
  const std::string dir = directory_of(target);
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw Error(ErrorCode::io_failure, target + ": directory " + dir + " does not exist");
  if (fs::is_directory(target, ec)) throw Error(ErrorCode::io_failure, target + ": is a directory");

  static std::atomic<unsigned> counter{0};
  std::string base = fs::path(target).filename().string();
  if (base.size() > 200) base.resize(200);  // NAME_MAX is 255 on the usual filesystems
  const std::string temporary = (fs::path(dir) / ("." + base + "." + std::to_string(::getpid()) + "." +
                                                  std::to_string(counter++) + kTemporarySuffix))
                                    .string();
  // Registered before it exists, so that no signal can come between creating and registering.
  Entry entry{target, temporary, claim_slot(temporary)};
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);  // less the umask
  if (fd < 0) {
    const int err = errno;
    release_slot(entry.slot);
    throw Error(ErrorCode::io_failure, target + ": cannot create a temporary file in " + dir + ": " + errno_text(err));
  }
  struct stat existing {};
  if (::stat(target.c_str(), &existing) == 0 && S_ISREG(existing.st_mode)) {
    (void)::fchmod(fd, existing.st_mode & 07777);  // keep the replaced file's permissions
  }
  ::close(fd);
  entries_.push_back(entry);  // from here on the destructor removes it

  try {
    writer(temporary);
  } catch (const Error& e) {
    throw Error(e.code(), replace_all(e.what(), temporary, target));
  } catch (const std::exception& e) {
    throw Error(ErrorCode::io_failure, target + ": cannot write: " + replace_all(e.what(), temporary, target));
  }
  try {
    fsync_path(temporary, false);
  } catch (const Error& e) {
    throw Error(e.code(), replace_all(e.what(), temporary, target));
  }
}

void AtomicOutputs::commit() {
  if (committed_) return;
  std::set<std::string> directories;
  {
    HoldSignals hold;
    for (size_t i = 0; i < entries_.size(); ++i) {
      Entry& e = entries_[i];
      if (::rename(e.temporary.c_str(), e.target.c_str()) != 0) {
        const int err = errno;
        // The files before this one are replaced already; the rest are removed by the destructor.
        entries_.erase(entries_.begin(), entries_.begin() + static_cast<std::ptrdiff_t>(i));
        throw Error(ErrorCode::io_failure,
                    e.target + ": cannot rename the finished temporary over it: " + errno_text(err));
      }
      release_slot(e.slot);
      e.slot = -1;
      directories.insert(directory_of(e.target));
    }
    committed_ = true;
  }
  for (const std::string& d : directories) fsync_path(d, true);
}

void write_text_file(const std::string& path, std::string_view text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw Error(ErrorCode::io_failure, path + ": cannot open for writing: " + errno_text(errno));
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out.flush();
  const int err = errno;
  out.close();
  if (!out) throw Error(ErrorCode::io_failure, path + ": write failed: " + errno_text(err));
}

}  // namespace glint::io
