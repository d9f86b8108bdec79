// The DeformClient module: the deformd C API (deform_c.h, libdeform_c) as a third-party library,
// per platform, from Source/ThirdParty/deform_c/ (scripts/bundle-unreal-plugin.sh fills it for
// Linux x86_64 from the build; the other platforms' libraries are built elsewhere:
// docs/clients/unreal.md). Not compiled in the project's CI: no Unreal toolchain there.
using System.IO;
using UnrealBuildTool;

public class DeformClient : ModuleRules
{
	public DeformClient(ReadOnlyTargetRules Target) : base(Target)
	{
		PCHUsage = PCHUsageMode.UseExplicitOrSharedPCHs;
		PublicDependencyModuleNames.AddRange(new string[] { "Core", "CoreUObject", "Engine", "Projects", "ProceduralMeshComponent" });

		string ThirdParty = Path.Combine(PluginDirectory, "Source", "ThirdParty", "deform_c");
		PublicIncludePaths.Add(Path.Combine(ThirdParty, "include"));

		if (Target.Platform == UnrealTargetPlatform.Linux)
		{
			// libdeform_c.so.0 (its SONAME, what the module asks the loader for) and the
			// libraries it needs (gRPC, protobuf, Abseil, OpenSSL...), found beside it through its
			// DT_RPATH, $ORIGIN: all staged into the plugin's binaries folder.
			string Lib = Path.Combine(ThirdParty, "lib", "Linux", "x86_64-unknown-linux-gnu");
			PublicAdditionalLibraries.Add(Path.Combine(Lib, "libdeform_c.so"));
			foreach (string File in Directory.EnumerateFiles(Lib))
			{
				RuntimeDependencies.Add(Path.Combine("$(PluginDir)", "Binaries", "ThirdParty", "deform_c", "Linux", Path.GetFileName(File)), File);
			}
			PublicDefinitions.Add("DEFORM_CLIENT_LIBRARY_DIR=TEXT(\"Binaries/ThirdParty/deform_c/Linux\")");
			PublicDefinitions.Add("DEFORM_CLIENT_LIBRARY=TEXT(\"libdeform_c.so.0\")");
		}
		else if (Target.Platform == UnrealTargetPlatform.Win64)
		{
			// deform_c.dll built with MSVC (its import library deform_c.lib), loaded on first use.
			string Lib = Path.Combine(ThirdParty, "lib", "Win64");
			PublicAdditionalLibraries.Add(Path.Combine(Lib, "deform_c.lib"));
			PublicDelayLoadDLLs.Add("deform_c.dll");
			RuntimeDependencies.Add(Path.Combine("$(PluginDir)", "Binaries", "ThirdParty", "deform_c", "Win64", "deform_c.dll"), Path.Combine(Lib, "deform_c.dll"));
			PublicDefinitions.Add("DEFORM_CLIENT_LIBRARY_DIR=TEXT(\"Binaries/ThirdParty/deform_c/Win64\")");
			PublicDefinitions.Add("DEFORM_CLIENT_LIBRARY=TEXT(\"deform_c.dll\")");
		}
		else if (Target.Platform == UnrealTargetPlatform.Android)
		{
			// arm64-v8a only (standalone headsets); DeformClient_APL.xml puts it in the APK.
			string Lib = Path.Combine(ThirdParty, "lib", "Android", "arm64-v8a");
			PublicAdditionalLibraries.Add(Path.Combine(Lib, "libdeform_c.so"));
			AdditionalPropertiesForReceipt.Add("AndroidPlugin", Path.Combine(ModuleDirectory, "DeformClient_APL.xml"));
			PublicDefinitions.Add("DEFORM_CLIENT_LIBRARY_DIR=TEXT(\"\")");
			PublicDefinitions.Add("DEFORM_CLIENT_LIBRARY=TEXT(\"libdeform_c.so\")");
		}
	}
}
