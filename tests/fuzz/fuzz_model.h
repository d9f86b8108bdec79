// A small knee phantom model shared by the request-conversion fuzz targets: built once, on first
// use, and kept for the whole run (requests are converted against it as the service converts them
// against a loaded mesh).
#pragma once

#include <cstdlib>
#include <memory>

#include "core/io/phantom.h"
#include "core/model/deformation_model.h"

namespace deform::fuzz {

inline const DeformationModel& PhantomModel() {
  static const std::shared_ptr<const DeformationModel> model = [] {
    auto phantom = MakeKneePhantom(300);
    if (!phantom.ok()) std::abort();
    auto built = DeformationModel::Build(std::move(phantom->mesh), std::move(phantom->skeleton),
                                         ModelOptions::Paper());
    if (!built.ok()) std::abort();
    return *built;
  }();
  return *model;
}

}  // namespace deform::fuzz
