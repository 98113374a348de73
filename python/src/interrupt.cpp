// Long runs with the GIL released, stopped by Ctrl-C or a raising callback (bindings.h).
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>

#include "python/src/bindings.h"

namespace femto::python {

void run_interruptible(const std::function<void()>& work, std::atomic<bool>& stop,
                       const std::function<void()>& poll, double tick) {
  std::mutex mutex;
  std::condition_variable cv;
  bool done = false;
  std::exception_ptr failure;
  std::optional<py::error_already_set> raised;  // the first Python exception (Ctrl-C, callback)
  std::exception_ptr failure_in_poll;
  {
    py::gil_scoped_release release;
    // Signals stay with the Python thread: Python's handler only sets a flag that
    // PyErr_CheckSignals below turns into KeyboardInterrupt.
    std::thread worker([&] {
      try {
        work();
      } catch (...) {
        failure = std::current_exception();
      }
      std::lock_guard<std::mutex> lock(mutex);
      done = true;
      cv.notify_all();
    });
    std::unique_lock<std::mutex> lock(mutex);
    while (!cv.wait_for(lock, std::chrono::duration<double>(tick), [&] { return done; })) {
      if (raised || failure_in_poll) continue;  // stopping: wait for the current pass to end
      lock.unlock();
      {
        py::gil_scoped_acquire acquire;
        try {
          if (PyErr_CheckSignals() != 0) throw py::error_already_set();
          if (poll) poll();
        } catch (py::error_already_set& e) {
          raised.emplace(std::move(e));
          stop.store(true);
        } catch (...) {
          if (!failure_in_poll) failure_in_poll = std::current_exception();
          stop.store(true);
        }
      }
      lock.lock();
    }
    lock.unlock();
    worker.join();
  }
  if (raised) throw *raised;
  if (failure_in_poll) std::rethrow_exception(failure_in_poll);
  if (failure) std::rethrow_exception(failure);
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();  // a signal in the last tick
  if (poll) poll();
}

}  // namespace femto::python
