// UDeformMeshComponent: a procedural mesh streamed from a deformd. BeginPlay connects, loads the
// built-in knee phantom (or opens a loaded mesh by id) and opens a stream on a worker thread
// (loads block while the server precomputes), then builds section 0 from the rest geometry. Each
// tick sends the joint angles if they changed (sending never waits for the network) and polls
// the newest frame with a zero timeout (a copy into a buffer allocated once; frames that arrived
// between two ticks replace each other), converts it to Unreal's frame and updates the section.
//
// Axes and units: deformd streams the mesh's own units in a right-handed frame; Unreal is
// left-handed, Z up, in centimeters. With CentimetersPerUnit s (the phantom: decimeters, 10):
//   Y-up mesh: Unreal (X, Y, Z) = s * (x, z, y);  Z-up mesh: Unreal (X, Y, Z) = s * (x, -y, z).
// Both are reflections, so each triangle's winding is reversed too.
// Written for Unreal Engine 5.1 or later; not compiled in the project's CI (no Unreal toolchain
// there): docs/clients/unreal.md.
#pragma once

#include "Async/Future.h"
#include "CoreMinimal.h"
#include "DeformMeshComponent.generated.h"
#include "ProceduralMeshComponent.h"
#include "deform_c.h"

USTRUCT(BlueprintType)
struct FDeformJointAngle {
  GENERATED_BODY()

  // A joint's name (or its index in decimal) and one of its degrees of freedom.
  UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Deformd")
  FString Joint = TEXT("knee");
  UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Deformd")
  FString Axis = TEXT("flexion");
  UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Deformd",
            meta = (ClampMin = "-180", ClampMax = "180"))
  float Degrees = 0;

  bool operator==(const FDeformJointAngle& Other) const {
    return Joint == Other.Joint && Axis == Other.Axis && Degrees == Other.Degrees;
  }
};

UENUM(BlueprintType)
enum class EDeformSourceUp : uint8 { Y, Z };

UCLASS(ClassGroup = (Deformd), meta = (BlueprintSpawnableComponent))
class DEFORMCLIENT_API UDeformMeshComponent : public UProceduralMeshComponent {
  GENERATED_BODY()

 public:
  UDeformMeshComponent(const FObjectInitializer& ObjectInitializer);

  UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Deformd|Server")
  FString Target = TEXT("127.0.0.1:50051");
  // Bearer token (deformd --token-file); empty: none.
  UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Deformd|Server")
  FString Token;
  // TLS: the CA's PEM file; empty: plaintext (loopback servers only).
  UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Deformd|Server")
  FString CaFile;

  // A loaded mesh's id; empty: a new built-in knee phantom.
  UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Deformd|Mesh")
  FString MeshId;
  UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Deformd|Mesh")
  int32 PhantomVertices = 0;
  // 1 float32, 2 quantized, 3 predicted (deform_encoding).
  UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Deformd|Mesh")
  int32 Encoding = DEFORM_ENCODING_PREDICTED;
  UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Deformd|Mesh")
  float CentimetersPerUnit = 10;
  UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Deformd|Mesh")
  EDeformSourceUp SourceUp = EDeformSourceUp::Y;

  UPROPERTY(EditAnywhere, BlueprintReadWrite, Category = "Deformd|Pose")
  TArray<FDeformJointAngle> JointAngles;

  // Sets one joint angle (adds it if missing); sent at the next tick.
  UFUNCTION(BlueprintCallable, Category = "Deformd")
  void SetJointAngle(const FString& Joint, const FString& Axis, float Degrees);

  void BeginPlay() override;
  void EndPlay(const EEndPlayReason::Type Reason) override;
  void TickComponent(float DeltaTime, ELevelTick TickType,
                     FActorComponentTickFunction* ThisTickFunction) override;

 private:
  // What the worker thread opened: the handles and the rest geometry in the server's frame.
  struct FOpened {
    deform_client* Client = nullptr;
    deform_mesh* Mesh = nullptr;
    deform_stream* Stream = nullptr;
    TArray<float> Rest;
    TArray<uint32> Triangles;
    FString Error;
  };
  static FOpened Open(FString Target, FString Token, FString CaFile, FString MeshId,
                      int32 PhantomVertices, int32 Encoding);
  static void Free(FOpened& Opened);
  FVector ToUnreal(const float* Position) const;
  void BuildSection();
  void SendPoseIfChanged();

  TFuture<FOpened> Opening;
  FOpened Stream;
  TArray<float> Positions;  // one frame, the server's frame: 3 floats per vertex
  TArray<FVector> Vertices;
  TArray<FDeformJointAngle> SentAngles;
};
