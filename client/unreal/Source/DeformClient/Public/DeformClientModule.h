// The DeformClient module: loads libdeform_c (the deformd C API) from the plugin's binaries at
// startup, so that the C calls of UDeformMeshComponent resolve, and releases it at shutdown.
// Not compiled in the project's CI (no Unreal toolchain there): docs/clients/unreal.md.
#pragma once

#include "Modules/ModuleManager.h"

DECLARE_LOG_CATEGORY_EXTERN(LogDeformClient, Log, All);

class FDeformClientModule : public IModuleInterface {
 public:
  void StartupModule() override;
  void ShutdownModule() override;

  // True once the library is loaded and answered deform_version().
  static bool IsLibraryLoaded();

 private:
  void* LibraryHandle = nullptr;
};
