// A fake transport under one stream handler (service/transport/stream_transport.h), for the stream
// fuzz targets: a client's script of requests, half-close, cancel and write failures is played
// against the handler, and every breach of the transport contract by the handler aborts.
//
// The handler's calls (StartRead, StartWrite, Finish; from the fuzz thread or a worker) only
// record what is pending; RunScriptedCall, on the fuzz thread, answers them one at a time, so a
// callback never runs inside one of those calls, one read and one write callback at most are in
// flight, OnCancel comes at most once and OnDone last. It aborts when the handler
// - starts a read while one is pending, or a write while one is in flight;
// - calls Finish twice, or while a write is in flight;
// - starts a read or a write after Finish, or calls anything after OnDone;
// - changes a message while its write is in flight;
// - stalls: nothing pending and no Finish for kStallLimit (its workers never answer).
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include "service/transport/stream_transport.h"

namespace deform::fuzz {

// One step of the client's script, played in order.
template <typename Request>
struct ClientStep {
  enum class Kind {
    kRequest,        // answers the next read with `request`
    kHalfClose,      // answers the next read (and every later one) with no request
    kCancel,         // the call is cancelled (OnCancel) at once
    kFailNextWrite,  // the next write to complete reports a failure
  };
  Kind kind = Kind::kRequest;
  Request request;
  // With a read and a write both pending: answer the read first (else the write completes first).
  bool before_writes = false;
};

// What happened in a call, for the targets' own checks.
struct CallRecord {
  std::string finish_status;  // "<code> <message>"
  bool finished_ok = false;
  // Before Finish was called:
  bool half_closed = false;
  bool cancelled = false;
  bool write_failed = false;
  int writes = 0;
};

inline constexpr std::chrono::seconds kStallLimit{5};

[[noreturn]] inline void ContractBroken(const char* what) {
  std::fprintf(stderr, "stream transport contract broken: %s\n", what);
  std::abort();
}

template <typename Request, typename Response>
class ScriptedTransport final : public service::StreamTransport<Request, Response> {
 public:
  void StartRead(Request* request) override {
    std::lock_guard<std::mutex> lock(mutex_);
    if (done_) ContractBroken("StartRead after OnDone");
    if (finished_) ContractBroken("StartRead after Finish");
    if (read_ != nullptr) ContractBroken("StartRead while a read is pending");
    read_ = request;
    changed_.notify_all();
  }

  void StartWrite(const Response* response) override {
    std::lock_guard<std::mutex> lock(mutex_);
    if (done_) ContractBroken("StartWrite after OnDone");
    if (finished_) ContractBroken("StartWrite after Finish");
    if (write_ != nullptr) ContractBroken("StartWrite while a write is in flight");
    write_ = response;
    write_bytes_ = response->SerializeAsString();
    changed_.notify_all();
  }

  void Finish(const grpc::Status& status) override {
    std::lock_guard<std::mutex> lock(mutex_);
    if (done_) ContractBroken("Finish after OnDone");
    if (finished_) ContractBroken("Finish called twice");
    if (write_ != nullptr) ContractBroken("Finish while a write is in flight");
    finished_ = true;
    record_.finished_ok = status.ok();
    record_.finish_status =
        std::to_string(static_cast<int>(status.error_code())) + " " + status.error_message();
    changed_.notify_all();
  }

  // Plays `script` against `handler` (made over this transport) until its OnDone, then returns what
  // happened. `on_written` sees every message whose write completed, ok or not.
  CallRecord Run(service::StreamHandler* handler, const std::vector<ClientStep<Request>>& script,
                 const std::function<void(const Response&)>& on_written) {
    std::size_t next = 0;
    bool half_closed = false;
    bool cancelled = false;
    bool fail_next_write = false;
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      // Steps that need no read: taken as soon as they come up.
      while (next < script.size() && !finished_) {
        const auto kind = script[next].kind;
        if (kind == ClientStep<Request>::Kind::kFailNextWrite) {
          fail_next_write = true;
        } else if (kind == ClientStep<Request>::Kind::kCancel) {
          if (!cancelled) {
            cancelled = true;
            record_.cancelled = true;
            lock.unlock();
            handler->OnCancel();
            lock.lock();
          }
        } else {
          break;
        }
        ++next;
      }
      if (finished_ && read_ == nullptr && write_ == nullptr) break;
      if (read_ == nullptr && write_ == nullptr) {
        if (!changed_.wait_for(lock, kStallLimit, [&] {
              return finished_ || read_ != nullptr || write_ != nullptr;
            })) {
          ContractBroken("stalled: no read, no write and no Finish");
        }
        continue;
      }
      const bool read_first =
          read_ != nullptr &&
          (write_ == nullptr || finished_ || (next < script.size() && script[next].before_writes));
      if (read_first) {
        Request* request = read_;
        read_ = nullptr;
        bool ok = false;
        if (!finished_ && !cancelled && !half_closed && next < script.size()) {
          if (script[next].kind == ClientStep<Request>::Kind::kRequest) {
            *request = script[next].request;
            ok = true;
          } else {
            half_closed = true;
          }
          ++next;
        } else if (!finished_ && !cancelled) {
          half_closed = true;  // the script's end is the client's half-close
        }
        if (half_closed && !finished_) record_.half_closed = true;
        lock.unlock();
        handler->OnReadDone(ok);
        lock.lock();
        continue;
      }
      const Response* response = write_;
      if (response->SerializeAsString() != write_bytes_) {
        ContractBroken("a message changed while its write was in flight");
      }
      const bool ok = !cancelled && !fail_next_write;
      fail_next_write = false;
      ++record_.writes;
      if (!ok && !finished_) record_.write_failed = true;
      lock.unlock();
      on_written(*response);
      {
        std::lock_guard<std::mutex> relock(mutex_);
        write_ = nullptr;
      }
      handler->OnWriteDone(ok);
      lock.lock();
    }
    done_ = true;
    lock.unlock();
    handler->OnDone();
    return record_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  Request* read_ = nullptr;          // the pending read's request
  const Response* write_ = nullptr;  // the write in flight
  std::string write_bytes_;          // its message as it was when the write started
  bool finished_ = false;
  bool done_ = false;
  CallRecord record_;
};

}  // namespace deform::fuzz
