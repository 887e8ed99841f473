#include "liftoff/core/output.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <mutex>
#include <random>
#include <system_error>

#include "liftoff/core/file.h"

namespace liftoff {

namespace fs = std::filesystem;

namespace {

// -- the registry the signal handler reads: fixed slots, no allocation, lock-free states

enum SlotState : int { kFree = 0, kClaimed = 1, kLive = 2 };
constexpr int kSlotCount = 64;
constexpr size_t kSlotPathBytes = 4096;

struct Slot {
  std::atomic<int> state{kFree};
  std::array<char, kSlotPathBytes> path{};
};
std::array<Slot, kSlotCount> g_slots;

constexpr std::array<int, 3> kCleanedSignals = {SIGINT, SIGTERM, SIGHUP};

// removes every live temporary file, then lets the signal do what it would have done
extern "C" void RemoveTemporariesAndReraise(int signal_number) {
  for (Slot& slot : g_slots) {
    if (slot.state.load() == kLive) unlink(slot.path.data());
  }
  struct sigaction default_action {};
  default_action.sa_handler = SIG_DFL;
  sigemptyset(&default_action.sa_mask);
  sigaction(signal_number, &default_action, nullptr);
  raise(signal_number);
}

// installs the handler once, only for signals whose action is still the default (a
// program's own handler, such as capture's orderly stop, wins)
void InstallSignalHandlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (int signal_number : kCleanedSignals) {
      struct sigaction current {};
      if (sigaction(signal_number, nullptr, &current) != 0) continue;
      if (current.sa_handler != SIG_DFL || (current.sa_flags & SA_SIGINFO) != 0) continue;
      struct sigaction action {};
      action.sa_handler = RemoveTemporariesAndReraise;
      sigemptyset(&action.sa_mask);
      sigaction(signal_number, &action, nullptr);
    }
  });
}

// a slot holding `path`, live before the file exists (a signal in between removes
// nothing, which is harmless); -1 when the registry is full or the path too long
int RegisterPath(const fs::path& path) {
  const std::string& text = path.native();
  if (text.size() >= kSlotPathBytes) return -1;
  for (int index = 0; index < kSlotCount; ++index) {
    Slot& slot = g_slots[static_cast<size_t>(index)];
    int expected = kFree;
    if (!slot.state.compare_exchange_strong(expected, kClaimed)) continue;
    std::memcpy(slot.path.data(), text.c_str(), text.size() + 1);
    slot.state.store(kLive);
    return index;
  }
  return -1;
}

void UnregisterPath(int slot) {
  if (slot >= 0) g_slots[static_cast<size_t>(slot)].state.store(kFree);
}

std::string SystemReason(int error_number) { return std::generic_category().message(error_number); }

// "<target>.tmp.<pid>.<16 hex digits>"
fs::path TemporaryNameFor(const fs::path& target) {
  static std::mutex mutex;
  static std::mt19937_64 generator{std::random_device{}()};
  uint64_t random = 0;
  {
    const std::lock_guard<std::mutex> lock(mutex);
    random = generator();
  }
  constexpr std::string_view kHex = "0123456789abcdef";
  std::string suffix(16, '0');
  for (char& digit : suffix) {
    digit = kHex[random & 0xf];
    random >>= 4;
  }
  fs::path name = target;
  name += ".tmp." + std::to_string(getpid()) + "." + suffix;
  return name;
}

// the paths' identity: the same inode when both exist, else the same canonical spelling
std::optional<fs::path> Resolved(const fs::path& path) {
  std::error_code error;
  fs::path resolved = fs::weakly_canonical(fs::absolute(path, error), error);
  if (error) return std::nullopt;
  return resolved;
}

bool IsFileName(const fs::path& path) { return !path.empty() && path != "-"; }

}  // namespace

// ---------------------------------------------------------------------------------------
// outputs against inputs

Status RefuseToReplace(const std::filesystem::path& path, std::string_view what, bool replace) {
  std::error_code error;
  if (replace || !std::filesystem::exists(std::filesystem::symlink_status(path, error))) {
    return Status::Ok();
  }
  const std::string said = what.empty() ? "" : " (" + std::string(what) + ")";
  return InvalidArgumentError(path.string() + ": exists" + said + "; pass --force to replace it");
}

bool SameFile(const fs::path& a, const fs::path& b) {
  std::error_code error;
  if (fs::exists(a, error) && fs::exists(b, error)) {
    const bool same = fs::equivalent(a, b, error);
    if (!error) return same;
  }
  const std::optional<fs::path> resolved_a = Resolved(a);
  const std::optional<fs::path> resolved_b = Resolved(b);
  if (resolved_a && resolved_b) return *resolved_a == *resolved_b;
  return fs::absolute(a, error).lexically_normal() == fs::absolute(b, error).lexically_normal();
}

Status CheckOutputsAreNotInputs(const std::vector<NamedPath>& outputs,
                                const std::vector<NamedPath>& inputs) {
  for (const NamedPath& output : outputs) {
    if (!IsFileName(output.path)) continue;
    for (const NamedPath& input : inputs) {
      if (!IsFileName(input.path) || !SameFile(output.path, input.path)) continue;
      return InvalidArgumentError(output.role + " " + output.path.string() +
                                  ": is the command's input " + input.role + " (" +
                                  input.path.string() + "); refusing to write over an input");
    }
  }
  return Status::Ok();
}

// ---------------------------------------------------------------------------------------
// TemporaryFile

Result<TemporaryFile> TemporaryFile::Create(const fs::path& target) {
  LIFTOFF_RETURN_IF_ERROR(CreateParentFolder(target));
  InstallSignalHandlers();
  // a fresh name until one is free (a clash needs the same pid and 64 random bits)
  for (int attempt = 0; attempt < 16; ++attempt) {
    fs::path path = TemporaryNameFor(target);
    const int slot = RegisterPath(path);
    const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) return TemporaryFile(target, std::move(path), fd, slot);
    const int error_number = errno;
    UnregisterPath(slot);
    if (error_number != EEXIST) {
      return IoError(target.string() + ": cannot create a temporary file beside it: " +
                     SystemReason(error_number));
    }
  }
  return IoError(target.string() + ": cannot create a temporary file beside it: every name taken");
}

TemporaryFile::TemporaryFile(fs::path target, fs::path path, int fd, int slot)
    : target_(std::move(target)), path_(std::move(path)), fd_(fd), slot_(slot) {}

TemporaryFile::TemporaryFile(TemporaryFile&& other) noexcept
    : target_(std::move(other.target_)),
      path_(std::move(other.path_)),
      fd_(other.fd_),
      slot_(other.slot_) {
  other.fd_ = -1;
  other.slot_ = -1;
  other.path_.clear();
}

TemporaryFile::~TemporaryFile() { Discard(); }

void TemporaryFile::Discard() {
  if (fd_ >= 0) close(fd_);
  fd_ = -1;
  if (!path_.empty()) unlink(path_.c_str());
  path_.clear();
  UnregisterPath(slot_);
  slot_ = -1;
}

Status TemporaryFile::Write(std::string_view bytes) {
  while (!bytes.empty()) {
    const ssize_t written = write(fd_, bytes.data(), bytes.size());
    if (written < 0 && errno == EINTR) continue;
    if (written < 0) {
      const int error_number = errno;
      return IoError(target_.string() + ": write failed: " + SystemReason(error_number));
    }
    bytes.remove_prefix(static_cast<size_t>(written));
  }
  return Status::Ok();
}

Status TemporaryFile::Commit() {
  const int fd = fd_;
  fd_ = -1;
  if (close(fd) != 0) {
    const int error_number = errno;
    Discard();
    return IoError(target_.string() + ": write failed: " + SystemReason(error_number));
  }
  if (rename(path_.c_str(), target_.c_str()) != 0) {
    const int error_number = errno;  // before anything else can overwrite it
    Discard();
    return IoError(target_.string() + ": cannot rename into place: " + SystemReason(error_number));
  }
  path_.clear();  // it is the target now
  UnregisterPath(slot_);
  slot_ = -1;
  return Status::Ok();
}

int LiveTemporaryFileCount() {
  int live = 0;
  for (const Slot& slot : g_slots) live += slot.state.load() == kLive ? 1 : 0;
  return live;
}

}  // namespace liftoff
