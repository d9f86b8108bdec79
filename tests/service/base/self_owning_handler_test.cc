// SelfOwningHandler: the transport's reference and the tasks' references, the last one frees.
#include "service/base/self_owning_handler.h"

#include <gtest/gtest.h>

#include <functional>
#include <memory>

namespace deform::service {
namespace {

// Counts its destruction in `*destroyed`; exposes the protected calls a reactor makes.
class FakeReactor : public SelfOwningHandler<FakeReactor> {
 public:
  explicit FakeReactor(int* destroyed) : destroyed_(destroyed) {}
  ~FakeReactor() { ++*destroyed_; }

  std::function<void()> MakeTask() {
    return [self = SharedFromThis()] { (void)self; };
  }
  void OnDone() { ReleaseTransportReference(); }

 private:
  int* const destroyed_;
};

TEST(SelfOwningHandlerTest, TheTransportReferenceAloneKeepsTheObjectUntilOnDone) {
  int destroyed = 0;
  FakeReactor* reactor = FakeReactor::Create(&destroyed);
  EXPECT_EQ(destroyed, 0);
  reactor->OnDone();
  EXPECT_EQ(destroyed, 1);
}

TEST(SelfOwningHandlerTest, APostedTaskOutlivingOnDoneFreesTheObjectWhenItGoes) {
  int destroyed = 0;
  FakeReactor* reactor = FakeReactor::Create(&destroyed);
  std::function<void()> task = reactor->MakeTask();
  reactor->OnDone();
  EXPECT_EQ(destroyed, 0);
  task();
  task = nullptr;
  EXPECT_EQ(destroyed, 1);
}

TEST(SelfOwningHandlerTest, TasksEndingBeforeOnDoneLeaveTheObjectToTheTransport) {
  int destroyed = 0;
  FakeReactor* reactor = FakeReactor::Create(&destroyed);
  {
    std::function<void()> first = reactor->MakeTask();
    std::function<void()> second = reactor->MakeTask();
  }
  EXPECT_EQ(destroyed, 0);
  reactor->OnDone();
  EXPECT_EQ(destroyed, 1);
}

}  // namespace
}  // namespace deform::service
