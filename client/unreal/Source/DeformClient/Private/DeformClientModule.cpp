// See DeformClientModule.h.
#include "DeformClientModule.h"

#include "HAL/PlatformProcess.h"
#include "Interfaces/IPluginManager.h"
#include "Misc/Paths.h"
#include "deform_c.h"

DEFINE_LOG_CATEGORY(LogDeformClient);

namespace {
bool GLibraryLoaded = false;
}

void FDeformClientModule::StartupModule() {
  // DEFORM_CLIENT_LIBRARY and its folder come from DeformClient.Build.cs, per platform. On
  // Android the APK's loader has already loaded it (DeformClient_APL.xml): the folder is empty.
  FString Directory = DEFORM_CLIENT_LIBRARY_DIR;
  FString Path = DEFORM_CLIENT_LIBRARY;
  if (!Directory.IsEmpty()) {
    TSharedPtr<IPlugin> Plugin = IPluginManager::Get().FindPlugin(TEXT("DeformClient"));
    if (Plugin.IsValid()) {
      Path = FPaths::Combine(Plugin->GetBaseDir(), Directory, DEFORM_CLIENT_LIBRARY);
    }
    LibraryHandle = FPlatformProcess::GetDllHandle(*Path);
    if (LibraryHandle == nullptr) {
      UE_LOG(LogDeformClient, Error, TEXT("could not load %s: the plugin's streams stay closed"),
             *Path);
      return;
    }
  }
  GLibraryLoaded = true;
  UE_LOG(LogDeformClient, Log, TEXT("deformd C API %s loaded from %s"),
         UTF8_TO_TCHAR(deform_version()), *Path);
}

void FDeformClientModule::ShutdownModule() {
  GLibraryLoaded = false;
  if (LibraryHandle != nullptr) {
    FPlatformProcess::FreeDllHandle(LibraryHandle);
    LibraryHandle = nullptr;
  }
}

bool FDeformClientModule::IsLibraryLoaded() { return GLibraryLoaded; }

IMPLEMENT_MODULE(FDeformClientModule, DeformClient)
