// StreamWritePump without gRPC: a fake stream (a FIFO of strings, and a flag for work still able
// to produce messages) and a fake transport that records what it was asked to do.
#include "service/transport/stream_write_pump.h"

#include <gtest/gtest.h>

#include <deque>
#include <string>
#include <vector>

namespace deform::service {
namespace {

class FakeStream final : public StreamWriteSource<std::string>,
                         public StreamWriteSink<std::string> {
 public:
  explicit FakeStream(FinishRule rule = FinishRule::kErrorOverridesGraceful)
      : pump(this, this, rule) {}

  void Queue(const std::string& message) { outbox.push_back(message); }

  // StreamWriteSource.
  const std::string* TakeNextWrite() override {
    if (outbox.empty()) return nullptr;
    in_flight = outbox.front();
    outbox.pop_front();
    return &in_flight;
  }
  void WriteCompleted(bool ok) override { completions.push_back(ok); }
  bool ReadyToFinish() override { return !work_running; }

  // StreamWriteSink.
  void StartWrite(const std::string* message) override {
    EXPECT_FALSE(writing) << "a second write while one is in flight";
    EXPECT_EQ(finishes, 0) << "a write after Finish";
    writing = true;
    written.push_back(*message);
  }
  void Finish(const grpc::Status& status) override {
    EXPECT_FALSE(writing) << "Finish while a write is in flight";
    ++finishes;
    final_status = status;
  }

  // The transport completes the write in flight.
  void CompleteWrite(bool ok = true) {
    ASSERT_TRUE(writing);
    writing = false;
    pump.OnWriteDone(ok);
  }

  StreamWritePump<std::string> pump;
  std::deque<std::string> outbox;
  std::string in_flight;
  bool work_running = false;
  bool writing = false;
  std::vector<std::string> written;
  std::vector<bool> completions;
  int finishes = 0;
  grpc::Status final_status;
};

const grpc::Status kUnavailable(grpc::StatusCode::UNAVAILABLE, "draining");
const grpc::Status kCancelled(grpc::StatusCode::CANCELLED, "cancelled by the client");

TEST(StreamWritePumpTest, WritesOneMessageAtATimeInOrder) {
  FakeStream stream;
  stream.Queue("a");
  stream.Queue("b");
  stream.pump.Pump();
  stream.pump.Pump();  // a write is in flight: nothing more
  EXPECT_EQ(stream.written, (std::vector<std::string>{"a"}));
  stream.Queue("c");
  stream.CompleteWrite();
  stream.CompleteWrite();
  stream.CompleteWrite();
  EXPECT_EQ(stream.written, (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_EQ(stream.completions, (std::vector<bool>{true, true, true}));
  EXPECT_EQ(stream.finishes, 0);
  EXPECT_FALSE(stream.pump.finish_requested());
}

TEST(StreamWritePumpTest, GracefulFinishWaitsForEveryMessageAndForRunningWork) {
  FakeStream stream;
  stream.Queue("a");
  stream.Queue("b");
  stream.work_running = true;
  stream.pump.Pump();
  stream.pump.RequestFinish(grpc::Status::OK);
  stream.pump.Pump();
  EXPECT_TRUE(stream.pump.finish_requested());
  EXPECT_FALSE(stream.pump.failing());
  stream.CompleteWrite();
  stream.CompleteWrite();
  EXPECT_EQ(stream.finishes, 0) << "finished while work could still produce a message";
  // The work produces a last message and ends.
  stream.Queue("c");
  stream.work_running = false;
  stream.pump.Pump();
  stream.CompleteWrite();
  EXPECT_EQ(stream.written, (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_EQ(stream.finishes, 1);
  EXPECT_TRUE(stream.final_status.ok());
  EXPECT_TRUE(stream.pump.finished());
}

TEST(StreamWritePumpTest, ErrorFinishesOnceTheWriteInFlightEndsAndDropsTheRest) {
  FakeStream stream;
  stream.Queue("a");
  stream.Queue("b");
  stream.work_running = true;
  stream.pump.Pump();
  stream.pump.RequestFinish(kUnavailable);
  stream.pump.Pump();
  EXPECT_TRUE(stream.pump.failing());
  EXPECT_EQ(stream.finishes, 0) << "Finish while a write is in flight";
  stream.CompleteWrite();
  EXPECT_EQ(stream.finishes, 1);
  EXPECT_EQ(stream.final_status.error_code(), grpc::StatusCode::UNAVAILABLE);
  EXPECT_EQ(stream.written, (std::vector<std::string>{"a"}));
  stream.Queue("c");
  stream.pump.Pump();
  EXPECT_EQ(stream.written.size(), 1u);
  EXPECT_EQ(stream.finishes, 1);
}

TEST(StreamWritePumpTest, ErrorWithNothingInFlightFinishesAtOnce) {
  FakeStream stream;
  stream.Queue("a");
  stream.pump.RequestFinish(kUnavailable);
  stream.pump.Pump();
  EXPECT_TRUE(stream.written.empty());
  EXPECT_EQ(stream.finishes, 1);
}

TEST(StreamWritePumpTest, FailedWriteFinishesCancelled) {
  FakeStream stream;
  stream.Queue("a");
  stream.Queue("b");
  stream.pump.Pump();
  stream.CompleteWrite(/*ok=*/false);
  EXPECT_EQ(stream.completions, (std::vector<bool>{false}));
  EXPECT_EQ(stream.finishes, 1);
  EXPECT_EQ(stream.final_status.error_code(), grpc::StatusCode::CANCELLED);
  EXPECT_EQ(stream.final_status.error_message(), "write failed");
  EXPECT_EQ(stream.written, (std::vector<std::string>{"a"}));
}

TEST(StreamWritePumpTest, ErrorOverridesGracefulFinishAndTheFirstErrorStands) {
  FakeStream stream(FinishRule::kErrorOverridesGraceful);
  stream.Queue("a");
  stream.Queue("b");
  stream.pump.Pump();
  stream.pump.RequestFinish(grpc::Status::OK);
  stream.pump.RequestFinish(kCancelled);
  stream.pump.RequestFinish(kUnavailable);
  stream.pump.RequestFinish(grpc::Status::OK);
  stream.CompleteWrite();
  EXPECT_EQ(stream.written, (std::vector<std::string>{"a"}));
  EXPECT_EQ(stream.finishes, 1);
  EXPECT_EQ(stream.final_status.error_code(), grpc::StatusCode::CANCELLED);
}

TEST(StreamWritePumpTest, FirstRequestWinsKeepsAGracefulFinishThroughALaterError) {
  FakeStream stream(FinishRule::kFirstRequestWins);
  stream.Queue("a");
  stream.Queue("b");
  stream.pump.Pump();
  stream.pump.RequestFinish(grpc::Status::OK);
  stream.pump.RequestFinish(kCancelled);
  EXPECT_FALSE(stream.pump.failing());
  stream.CompleteWrite(/*ok=*/false);  // the write-failed request is ignored too
  stream.CompleteWrite();
  EXPECT_EQ(stream.written, (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(stream.finishes, 1);
  EXPECT_TRUE(stream.final_status.ok());
}

TEST(StreamWritePumpTest, FirstRequestWinsKeepsTheFirstError) {
  FakeStream stream(FinishRule::kFirstRequestWins);
  stream.pump.RequestFinish(kCancelled);
  stream.pump.RequestFinish(kUnavailable);
  stream.pump.Pump();
  EXPECT_EQ(stream.finishes, 1);
  EXPECT_EQ(stream.final_status.error_code(), grpc::StatusCode::CANCELLED);
}

TEST(StreamWritePumpTest, NothingReachesTheTransportAfterFinish) {
  FakeStream stream;
  stream.pump.RequestFinish(grpc::Status::OK);
  stream.pump.Pump();
  ASSERT_EQ(stream.finishes, 1);
  stream.Queue("late");
  stream.pump.RequestFinish(kUnavailable);
  stream.pump.Pump();
  stream.pump.Pump();
  EXPECT_TRUE(stream.written.empty());
  EXPECT_EQ(stream.finishes, 1);
  EXPECT_TRUE(stream.pump.finish_status().ok());
}

}  // namespace
}  // namespace deform::service
