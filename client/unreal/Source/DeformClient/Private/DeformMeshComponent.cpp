// See DeformMeshComponent.h.
#include "DeformMeshComponent.h"

#include "Async/Async.h"
#include "DeformClientModule.h"

UDeformMeshComponent::UDeformMeshComponent(const FObjectInitializer& ObjectInitializer)
    : Super(ObjectInitializer) {
  PrimaryComponentTick.bCanEverTick = true;
  JointAngles.Add(FDeformJointAngle());
}

void UDeformMeshComponent::SetJointAngle(const FString& Joint, const FString& Axis, float Degrees) {
  for (FDeformJointAngle& Angle : JointAngles) {
    if (Angle.Joint == Joint && Angle.Axis == Axis) {
      Angle.Degrees = Degrees;
      return;
    }
  }
  FDeformJointAngle& Added = JointAngles.AddDefaulted_GetRef();
  Added.Joint = Joint;
  Added.Axis = Axis;
  Added.Degrees = Degrees;
}

UDeformMeshComponent::FOpened UDeformMeshComponent::Open(FString Target, FString Token,
                                                         FString CaFile, FString MeshId,
                                                         int32 PhantomVertices, int32 Encoding) {
  FOpened Opened;
  auto Failed = [&Opened](const char* Call) {
    Opened.Error =
        FString::Printf(TEXT("%s: %s"), UTF8_TO_TCHAR(Call), UTF8_TO_TCHAR(deform_last_error()));
    Free(Opened);
    return MoveTemp(Opened);
  };
  FTCHARToUTF8 TargetText(*Target), TokenText(*Token), CaText(*CaFile), IdText(*MeshId);
  deform_connect_options Options = {};
  Options.target = TargetText.Get();
  Options.token = Token.IsEmpty() ? nullptr : TokenText.Get();
  Options.tls = CaFile.IsEmpty() ? 0 : 1;
  Options.ca_file = CaFile.IsEmpty() ? nullptr : CaText.Get();
  if (deform_connect(&Options, &Opened.Client) != DEFORM_OK) return Failed("deform_connect");
  deform_status Loaded =
      MeshId.IsEmpty() ? deform_load_phantom(Opened.Client, PhantomVertices, "unreal", &Opened.Mesh)
                       : deform_mesh_open(Opened.Client, IdText.Get(), &Opened.Mesh);
  if (Loaded != DEFORM_OK) return Failed("loading the mesh");
  const char* Id = nullptr;
  uint32_t VertexCount = 0, TriangleCount = 0;
  if (deform_mesh_id(Opened.Mesh, &Id) != DEFORM_OK ||
      deform_mesh_vertex_count(Opened.Mesh, &VertexCount) != DEFORM_OK ||
      deform_mesh_triangle_count(Opened.Mesh, &TriangleCount) != DEFORM_OK) {
    return Failed("describing the mesh");
  }
  Opened.Rest.SetNumUninitialized(3 * VertexCount);
  Opened.Triangles.SetNumUninitialized(3 * TriangleCount);
  if (deform_mesh_rest_geometry(Opened.Mesh, Opened.Rest.GetData(), Opened.Rest.Num(),
                                Opened.Triangles.GetData(), Opened.Triangles.Num()) != DEFORM_OK) {
    return Failed("deform_mesh_rest_geometry");
  }
  if (deform_stream_open(Opened.Client, Id, static_cast<deform_encoding>(Encoding), 0,
                         &Opened.Stream) != DEFORM_OK) {
    return Failed("deform_stream_open");
  }
  return Opened;
}

void UDeformMeshComponent::Free(FOpened& Opened) {
  if (Opened.Stream != nullptr) {
    deform_stream_close(Opened.Stream, 1000);
    deform_stream_free(Opened.Stream);
  }
  if (Opened.Mesh != nullptr) deform_mesh_free(Opened.Mesh);
  if (Opened.Client != nullptr) deform_client_free(Opened.Client);
  Opened.Stream = nullptr;
  Opened.Mesh = nullptr;
  Opened.Client = nullptr;
}

FVector UDeformMeshComponent::ToUnreal(const float* P) const {
  const double S = CentimetersPerUnit;
  return SourceUp == EDeformSourceUp::Y ? FVector(S * P[0], S * P[2], S * P[1])
                                        : FVector(S * P[0], -S * P[1], S * P[2]);
}

void UDeformMeshComponent::BeginPlay() {
  Super::BeginPlay();
  if (!FDeformClientModule::IsLibraryLoaded()) return;
  // Loads block while the server precomputes: on a worker thread, never the game thread.
  Opening = Async(EAsyncExecution::ThreadPool,
                  [Target = Target, Token = Token, CaFile = CaFile, MeshId = MeshId,
                   PhantomVertices = PhantomVertices, Encoding = Encoding]() {
                    return Open(Target, Token, CaFile, MeshId, PhantomVertices, Encoding);
                  });
}

void UDeformMeshComponent::BuildSection() {
  const int32 VertexCount = Stream.Rest.Num() / 3;
  Positions = Stream.Rest;
  Vertices.SetNumUninitialized(VertexCount);
  for (int32 V = 0; V < VertexCount; ++V) Vertices[V] = ToUnreal(&Positions[3 * V]);
  // The conversion is a reflection: each triangle's winding reversed.
  TArray<int32> Triangles;
  Triangles.SetNumUninitialized(Stream.Triangles.Num());
  for (int32 T = 0; T + 2 < Triangles.Num(); T += 3) {
    Triangles[T] = Stream.Triangles[T];
    Triangles[T + 1] = Stream.Triangles[T + 2];
    Triangles[T + 2] = Stream.Triangles[T + 1];
  }
  CreateMeshSection_LinearColor(0, Vertices, Triangles, {}, {}, {}, {}, /*bCreateCollision=*/false);
}

void UDeformMeshComponent::SendPoseIfChanged() {
  if (JointAngles == SentAngles) return;
  // The names as NUL-terminated UTF-8, alive until the call returns (the library copies them).
  TArray<TArray<ANSICHAR>> Names;
  auto Utf8 = [&Names](const FString& Text) {
    FTCHARToUTF8 Converted(*Text);
    TArray<ANSICHAR>& Name = Names.AddDefaulted_GetRef();
    Name.Append(Converted.Get(), Converted.Length());
    Name.Add('\0');
  };
  for (const FDeformJointAngle& Angle : JointAngles) {
    Utf8(Angle.Joint);
    Utf8(Angle.Axis);
  }
  TArray<deform_joint_angle> Angles;
  for (int32 I = 0; I < JointAngles.Num(); ++I) {
    Angles.Add(deform_joint_angle{Names[2 * I].GetData(), Names[2 * I + 1].GetData(),
                                  JointAngles[I].Degrees});
  }
  uint64_t Sequence = 0;
  if (deform_stream_send_pose(Stream.Stream, Angles.GetData(), Angles.Num(), nullptr, 0, nullptr,
                              &Sequence) != DEFORM_OK) {
    UE_LOG(LogDeformClient, Warning, TEXT("deform_stream_send_pose: %s"),
           UTF8_TO_TCHAR(deform_last_error()));
  }
  SentAngles = JointAngles;
}

void UDeformMeshComponent::TickComponent(float DeltaTime, ELevelTick TickType,
                                         FActorComponentTickFunction* ThisTickFunction) {
  Super::TickComponent(DeltaTime, TickType, ThisTickFunction);
  if (Stream.Stream == nullptr) {
    if (!Opening.IsValid() || !Opening.IsReady()) return;
    Stream = Opening.Consume();
    Opening = TFuture<FOpened>();
    if (!Stream.Error.IsEmpty()) {
      UE_LOG(LogDeformClient, Error, TEXT("%s"), *Stream.Error);
      SetComponentTickEnabled(false);
      return;
    }
    BuildSection();
  }
  SendPoseIfChanged();
  deform_frame_info Info;
  deform_status Status =
      deform_stream_next_frame(Stream.Stream, Positions.GetData(), Positions.Num(), 0, &Info);
  if (Status == DEFORM_NO_DATA) return;
  if (Status != DEFORM_OK) {
    UE_LOG(LogDeformClient, Warning, TEXT("deform_stream_next_frame: %s"),
           UTF8_TO_TCHAR(deform_last_error()));
    SetComponentTickEnabled(false);
    return;
  }
  for (int32 V = 0; V < Vertices.Num(); ++V) Vertices[V] = ToUnreal(&Positions[3 * V]);
  UpdateMeshSection_LinearColor(0, Vertices, {}, {}, {}, {});
}

void UDeformMeshComponent::EndPlay(const EEndPlayReason::Type Reason) {
  if (Opening.IsValid()) {
    // Still loading: wait for it, so that nothing it opened is left behind.
    Stream = Opening.Consume();
    Opening = TFuture<FOpened>();
  }
  Free(Stream);
  Super::EndPlay(Reason);
}
