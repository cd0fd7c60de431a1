#include "sim/rest/finish_thread.hpp"

#include <algorithm>
#include <cerrno>
#include <stdexcept>

#if defined(__linux__)
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

namespace drape::sim {

FinishThread::~FinishThread() {
  if (thread_.joinable()) {
    cancel();
    thread_.join();
  }
}

void FinishThread::start(const Cloth& cloth, const SceneObjects& scene,
                         const std::vector<int>& group, const EnergyOptions& energy_options,
                         const FinisherOptions& options) {
  if (busy()) throw std::logic_error("FinishThread::start: a job is still busy");
  if (static_cast<int>(group.size()) != cloth.num_vertices())
    throw std::invalid_argument("FinishThread::start: group has " + std::to_string(group.size()) +
                                " entries for " + std::to_string(cloth.num_vertices()) +
                                " vertices");
  // Written before the thread exists (its creation orders them before anything it reads).
  cloth_ = cloth;
  start_ = cloth.state.x;
  scene_ = scene;
  group_ = group;
  energy_options_ = energy_options;
  finisher_.options() = options;
  stats_ = FinisherStats{};
  completed_ = false;
  cancel_.store(false, std::memory_order_relaxed);
  done_.store(false, std::memory_order_relaxed);
  thread_ = std::thread([this] { work(); });
}

void FinishThread::work() {
#if defined(__linux__)
  // Linux keeps a nice value per thread: PRIO_PROCESS with this thread's id changes only it
  // (and the threads it creates: CHOLMOD's OpenMP team inherits it).
  const auto tid = static_cast<id_t>(syscall(SYS_gettid));
  if (nice_ != 0) {
    errno = 0;
    const int now = getpriority(PRIO_PROCESS, tid);
    if (errno == 0) setpriority(PRIO_PROCESS, tid, std::min(19, now + nice_));
  }
  errno = 0;
  job_nice_ = getpriority(PRIO_PROCESS, tid);
#endif
  stats_ = finisher_.run(cloth_, scene_, group_, energy_options_, nullptr, &cancel_);
  completed_ = !cancel_.load(std::memory_order_relaxed);
  done_.store(true, std::memory_order_release);
}

FinisherStats FinishThread::collect() {
  if (thread_.joinable()) thread_.join();
  return stats_;
}

}  // namespace drape::sim
