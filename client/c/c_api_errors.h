// The C API's error contract in one place: the calling thread's last-error message, the mapping
// from gRPC statuses to deform_status, and the guard that keeps C++ exceptions inside the library.
#pragma once

#include <grpcpp/support/status.h>

#include <exception>
#include <initializer_list>
#include <new>
#include <string>

#include "deform_c.h"

namespace deform::c_api {

// Sets this thread's last error to `message` and returns `status` (DEFORM_OK clears it).
deform_status Fail(deform_status status, std::string message);
deform_status Succeed();
// A gRPC status as deform_status (same numbers) with its message as the last error; `context`
// (e.g. "LoadMesh") prefixes the message when non-empty.
deform_status FromGrpc(const grpc::Status& status, const std::string& context = "");

// Runs `body` (returning deform_status) and turns any exception into a status: bad_alloc into
// RESOURCE_EXHAUSTED, anything else into INTERNAL naming what() where there is one.
// `function` is the C function's name: take __func__ outside the lambda (inside, it names the
// lambda's operator()).
template <typename Body>
deform_status Guarded(const char* function, Body&& body) noexcept {
  try {
    return body();
  } catch (const std::bad_alloc&) {
    return Fail(DEFORM_RESOURCE_EXHAUSTED, std::string(function) + ": out of memory");
  } catch (const std::exception& error) {
    return Fail(DEFORM_INTERNAL, std::string(function) + ": unexpected error: " + error.what());
  } catch (...) {
    return Fail(DEFORM_INTERNAL, std::string(function) + ": unexpected error");
  }
}

// A pointer parameter that must not be null, and its name.
struct Required {
  const void* pointer;
  const char* name;
};

// Guarded(function, body), but first INVALID_ARGUMENT naming the first of `required` that is
// null, if one is (`body` then does not run).
template <typename Body>
deform_status Guarded(const char* function, std::initializer_list<Required> required,
                      Body&& body) noexcept {
  return Guarded(function, [&] {
    for (const Required& parameter : required) {
      if (parameter.pointer == nullptr) {
        return Fail(DEFORM_INVALID_ARGUMENT,
                    std::string(function) + ": " + parameter.name + " is NULL");
      }
    }
    return body();
  });
}

// A getter's whole body: INVALID_ARGUMENT naming the parameter when `object` or `out` is null,
// else *out = read(*object) and DEFORM_OK. `function` as for Guarded.
template <typename Object, typename Out, typename Read>
deform_status Get(const char* function, const Object* object, const char* object_name, Out* out,
                  const char* out_name, Read&& read) noexcept {
  return Guarded(function, {{object, object_name}, {out, out_name}}, [&] {
    *out = read(*object);
    return Succeed();
  });
}

}  // namespace deform::c_api
