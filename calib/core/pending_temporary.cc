#include "calib/core/pending_temporary.h"

#include <unistd.h>
#include <climits>
#include <csignal>
#include <cstring>

#include <atomic>
#include <mutex>

#include "calib/core/signal_safe_removal.h"

namespace stereorig {

namespace {

// A slot's path and kind are written before it is marked ready, and the
// handler reads only ready slots: a signal between the two sees a free slot.
// Lock-free atomics, unlink(2), rmdir(2) and RemoveTreeSignalSafe are what a
// signal handler may use.
enum SlotState : int { kFree = 0, kFilling = 1, kReady = 2 };
struct Slot {
  std::atomic<int> state{kFree};
  TemporaryKind kind = TemporaryKind::kFile;
  char path[PATH_MAX];
};
static_assert(std::atomic<int>::is_always_lock_free);
Slot g_slots[PendingTemporary::kMaxPending];

// SIGPIPE too: a run whose stdout or stderr reader went away (simulate
// reports its progress on stderr while it writes its temporary dataset).
constexpr int kSignals[] = {SIGTERM, SIGINT, SIGHUP, SIGPIPE};

extern "C" void RemovePendingAndDie(int signal) {
  for (Slot& slot : g_slots) {
    if (slot.state.load() != kReady) continue;
    if (slot.kind == TemporaryKind::kFolder)
      RemoveTreeSignalSafe(slot.path);
    else if (slot.kind == TemporaryKind::kFile)
      unlink(slot.path);
  }
  // Then the empty folders, now that what was in them is gone. A folder is
  // emptied by removing the ones in it, whatever slots they hold: passes
  // until one removes nothing (rmdir fails on a folder not empty, or gone).
  for (bool removed = true; removed;) {
    removed = false;
    for (Slot& slot : g_slots)
      if (slot.state.load() == kReady && slot.kind == TemporaryKind::kEmptyFolder && rmdir(slot.path) == 0)
        removed = true;
  }
  std::signal(signal, SIG_DFL);
  raise(signal);
}

void InstallHandlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (const int signal : kSignals) {
      struct sigaction current {};
      if (sigaction(signal, nullptr, &current) != 0 || current.sa_handler != SIG_DFL) continue;
      struct sigaction handler {};
      handler.sa_handler = RemovePendingAndDie;
      sigemptyset(&handler.sa_mask);
      sigaction(signal, &handler, nullptr);
    }
  });
}

}  // namespace

PendingTemporary::PendingTemporary(const std::string& path, TemporaryKind kind) {
  if (path.size() >= PATH_MAX) return;
  InstallHandlers();
  for (int i = 0; i < kMaxPending; ++i) {
    int expected = kFree;
    if (!g_slots[i].state.compare_exchange_strong(expected, kFilling)) continue;
    std::memcpy(g_slots[i].path, path.c_str(), path.size() + 1);
    g_slots[i].kind = kind;
    g_slots[i].state.store(kReady);
    slot_ = i;
    return;
  }
}

void PendingTemporary::Release() {
  if (slot_ < 0) return;
  g_slots[slot_].state.store(kFree);
  slot_ = -1;
}

}  // namespace stereorig
