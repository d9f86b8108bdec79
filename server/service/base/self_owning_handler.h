// Ownership of an object that a transport calls back through a raw pointer until its last
// callback, and that worker tasks may outlive: a gRPC callback reactor (and a WebSocket
// connection's handler).
//
// gRPC's callback API takes a raw reactor pointer from the service method, calls the reactor's
// reactions until OnDone(), its last one, and requires the reactor to stay alive until OnDone()
// has been called; it never touches the reactor after that. Worker tasks the reactor posted
// (solves, refactorizations, mesh builds) may still run after OnDone(). So the reactor is owned by
// shared_ptrs and nothing else:
//  - the transport's reference, which the object keeps to itself from Create() until the
//    transport's last callback calls ReleaseTransportReference();
//  - one per posted task: a background task's capture of SharedFromThis(), or the worker pool's
//    reference to a queued FrameTask (worker_pool.h).
// The last reference to go frees the object; shared_ptr's deleter is the one place a reactor is
// freed, and nothing counts holds by hand.
//
// Thread safety: Create() and ReleaseTransportReference() are called once each, by the service
// method and by the last callback; SharedFromThis() from any thread that holds a reference (any
// reaction before the last callback, any posted task).
#pragma once

#include <memory>
#include <utility>

namespace deform::service {

template <typename Derived>
class SelfOwningHandler : public std::enable_shared_from_this<Derived> {
 public:
  // A new Derived(args...) holding the transport's reference to itself; the raw pointer is for the
  // transport, which must end with a call that leads to ReleaseTransportReference().
  template <typename... Args>
  static Derived* Create(Args&&... args) {
    std::shared_ptr<Derived> object = std::make_shared<Derived>(std::forward<Args>(args)...);
    object->transport_reference_ = object;
    return object.get();
  }

 protected:
  SelfOwningHandler() = default;
  ~SelfOwningHandler() = default;
  SelfOwningHandler(const SelfOwningHandler&) = delete;
  SelfOwningHandler& operator=(const SelfOwningHandler&) = delete;

  // A reference for a task the object posts.
  std::shared_ptr<Derived> SharedFromThis() { return this->shared_from_this(); }

  // Gives up the transport's reference; the object is freed now if no task holds one, so this is
  // the last thing the transport's last callback (gRPC's OnDone) does.
  void ReleaseTransportReference() {
    std::shared_ptr<Derived> last = std::move(transport_reference_);
  }

 private:
  std::shared_ptr<Derived> transport_reference_;
};

}  // namespace deform::service
