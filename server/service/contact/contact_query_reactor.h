// The QueryContact RPC: one handler per call, owned like the Deform stream's
// (self_owning_handler.h), over the transport contract (stream_transport.h).
//
// `start` finds the mesh as the caller may see it (another tenant's is NOT_FOUND), and the
// Deform stream it names, if any, in the context's latest frames (another tenant's, or one on
// another mesh, is NOT_FOUND as an unknown id); it counts the stream against the tenant's stream
// limit and holds the query's memory (its tree and a frame's positions) in the tenant's budget.
// It builds the stream's own bounding-volume tree over the rest skin (SkinContactQuery) and
// answers `started`.
//
// Each query is answered in OnReadDone on the transport's thread: a query is one descent of the
// tree (logarithmic in the triangles), plus, when the named Deform stream has published a frame
// newer than the tree's, one copy of its positions and one refit (linear in the triangles): the
// frame path pays nothing for queries, and a query pays no queueing behind frames. The next read
// starts only when the result is written, so a stream holds one query at a time and the server
// does one query's work per round trip of each stream: that is the flood bound.
//
// Ends with OK after the client half-closes, INVALID_ARGUMENT for a bad start or query (naming
// it), CANCELLED when the client cancels, UNAVAILABLE when the server drains, UNAUTHENTICATED
// when its token is revoked.
#pragma once

#include "deform/v1/deform.pb.h"
#include "service/access/identity.h"
#include "service/context/service_context.h"
#include "service/transport/stream_transport.h"

namespace deform::service {

using ContactQueryTransport = StreamTransport<v1::QueryContactRequest, v1::QueryContactResponse>;

// A new handler for one QueryContact call over `transport`; it starts reading at once. `context`
// and the transport must outlive it (the transport until its OnDone()).
StreamHandler* NewContactQueryStream(ServiceContext* context, Identity caller,
                                     ContactQueryTransport* transport);

}  // namespace deform::service
