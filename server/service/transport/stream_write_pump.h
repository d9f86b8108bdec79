// The write side of a server stream, written once for every streaming RPC and every transport:
// at most one write in flight, the next message chosen by the stream, and the stream's end.
//
//  - The stream (a StreamWriteSource) says what to write next and when it may end gracefully: the
//    Deform stream writes its latest-wins frame slot and its notices in order, LoadMesh its FIFO
//    of progress messages.
//  - The transport (a StreamWriteSink) starts a write and ends the stream: gRPC's reactor
//    (grpc_stream_adapter.h) or a WebSocket session (transport/websocket_session.h), both through
//    stream_transport.h. Nothing here depends on grpc::ServerBidiReactor;
//    grpc::Status is only the value type of the final status (its canonical codes).
//
// The protocol:
//  - Pump() starts a write when none is in flight and the source has a message; the transport
//    reports the write's end through OnWriteDone(), which pumps again.
//  - RequestFinish(OK) ends the stream once nothing is left: no message to write and the source
//    ReadyToFinish(). RequestFinish(error) ends it as soon as no write is in flight; unwritten
//    messages are dropped and no new write starts (the source should stop producing: failing()).
//  - A failed write (OnWriteDone(false)) requests a CANCELLED finish ("write failed").
//  - A second request follows the FinishRule; Finish() reaches the transport exactly once, and
//    after it no write starts and requests change nothing.
//
// Thread safety: none of its own. Every call is made under the owner's lock, the lock that also
// guards the source's state (the owner declares the pump DEFORM_GUARDED_BY that lock); the source's
// and the sink's hooks are called back under it, from inside RequestFinish(), Pump() and
// OnWriteDone(). No allocation.
#pragma once

#include <grpcpp/support/status.h>

namespace deform::service {

// What a stream writes, and when it may end. Hooks are called under the owner's lock.
template <typename Message>
class StreamWriteSource {
 public:
  // Takes the next message to write out of the stream's queue, or nullptr when none is ready. It
  // must stay valid and unchanged until its write completes (the next WriteCompleted()).
  virtual const Message* TakeNextWrite() = 0;
  // The write of the last message taken has completed; `ok` false when the transport failed.
  virtual void WriteCompleted(bool ok) = 0;
  // Whether a graceful finish may happen now: nothing left that could still produce a message.
  // Asked only when TakeNextWrite() has just returned nullptr.
  virtual bool ReadyToFinish() = 0;

 protected:
  ~StreamWriteSource() = default;
};

// The transport under a stream. Hooks are called under the owner's lock.
template <typename Message>
class StreamWriteSink {
 public:
  // Starts writing `message`; the transport then calls the pump's OnWriteDone(). Never called
  // while a write is in flight.
  virtual void StartWrite(const Message* message) = 0;
  // Ends the stream with `status`. Called once, never while a write is in flight.
  virtual void Finish(const grpc::Status& status) = 0;

 protected:
  ~StreamWriteSink() = default;
};

// What a second finish request does.
enum class FinishRule {
  // An error replaces a pending graceful finish (the stream then ends at once); the first error
  // stands. The Deform stream: a cancel or a drain during the final writes ends it now.
  kErrorOverridesGraceful,
  // The first request stands, whatever comes later. LoadMesh: once READY is queued with an OK
  // finish, a later cancel or failed write does not change the status.
  kFirstRequestWins,
};

template <typename Message>
class StreamWritePump {
 public:
  // `source` and `sink` must outlive the pump (usually all three are the same reactor's).
  StreamWritePump(StreamWriteSource<Message>* source, StreamWriteSink<Message>* sink,
                  FinishRule rule)
      : source_(source), sink_(sink), rule_(rule) {}
  StreamWritePump(const StreamWritePump&) = delete;
  StreamWritePump& operator=(const StreamWritePump&) = delete;

  // Asks for the stream to end with `status` (see the protocol above). Call Pump() after it.
  void RequestFinish(const grpc::Status& status) {
    if (finished_) return;  // the transport has its status
    if (finish_requested_ && (rule_ == FinishRule::kFirstRequestWins || failing() || status.ok())) {
      return;
    }
    finish_requested_ = true;
    finish_status_ = status;
  }

  // Starts the next write, or the finish, if one is due. Call it after anything that may have
  // given the source a message or made it ready to finish.
  void Pump() {
    if (finished_ || write_in_flight_) return;
    if (failing()) {
      Finish();
      return;
    }
    if (const Message* next = source_->TakeNextWrite()) {
      write_in_flight_ = true;
      sink_->StartWrite(next);
      return;
    }
    if (finish_requested_ && source_->ReadyToFinish()) Finish();
  }

  // The transport's report that the write in flight has ended.
  void OnWriteDone(bool ok) {
    write_in_flight_ = false;
    source_->WriteCompleted(ok);
    if (!ok) RequestFinish(grpc::Status(grpc::StatusCode::CANCELLED, "write failed"));
    Pump();
  }

  // A finish (of any status) has been requested: read no more requests.
  bool finish_requested() const { return finish_requested_; }
  // An error finish has been requested: start no more work, nothing more will be written.
  bool failing() const { return finish_requested_ && !finish_status_.ok(); }
  // The transport has been told to finish.
  bool finished() const { return finished_; }
  // The status requested (OK until an error is requested); once finished, the one sent.
  const grpc::Status& finish_status() const { return finish_status_; }

 private:
  void Finish() {
    finished_ = true;
    sink_->Finish(finish_status_);
  }

  StreamWriteSource<Message>* const source_;
  StreamWriteSink<Message>* const sink_;
  const FinishRule rule_;
  bool write_in_flight_ = false;
  bool finish_requested_ = false;
  bool finished_ = false;
  grpc::Status finish_status_;
};

}  // namespace deform::service
