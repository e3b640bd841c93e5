#include "stream_reactor.h"

#include <grpcpp/support/proto_buffer_reader.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <mutex>
#include <string>

#include "session/input_rules.h"
#include "session/outgoing_messages.h"
#include "status.h"

namespace fluidcast::server {

// One message being written, the rest in OutgoingMessages. Reached from the worker, the encoders
// and the reactions, so all under a lock.
class GrpcViewerSink final : public ViewerSink {
 public:
  GrpcViewerSink(StreamReactor* reactor, Metrics& metrics)
      : reactor_(reactor), metrics_(&metrics) {}

  bool deliver(std::shared_ptr<const v1::ServerMessage> message) override {
    std::lock_guard lock(mutex_);
    if (!reactor_ || finishing_) return true;
    const bool kept = outgoing_.push(std::move(message));
    if (!writing_) write_next();
    return kept;
  }

  // The stream's rules or its session end it: counted and logged once, as it finishes.
  void end(const Refusal& why) override {
    if (finish(to_status(why))) record_refusal(*metrics_, Transport::grpc, why);
  }

  // Ends a stream that has sent no Hello yet; false when one came meanwhile (or it is ending).
  bool end_unopened(const Refusal& why) {
    std::lock_guard lock(mutex_);
    if (!reactor_ || finishing_ || hello_came_) return false;
    finishing_ = true;
    reactor_->Finish(to_status(why));
    record_refusal(*metrics_, Transport::grpc, why);
    return true;
  }
  // The first message came: the deadline is met, unless the stream is ending already (the
  // deadline's alarm ran first, or the client cancelled), when the message opens nothing.
  bool hello_came() {
    std::lock_guard lock(mutex_);
    hello_came_ = true;
    return reactor_ && !finishing_;
  }

  // Finishes the stream with `status` once; false when it is finishing already (or gone).
  bool finish(const grpc::Status& status) {
    std::lock_guard lock(mutex_);
    if (!reactor_ || finishing_) return false;
    finishing_ = true;
    outgoing_.stop_frames();
    if (writing_) {
      status_after_write_ = status;
    } else {
      reactor_->Finish(status);
    }
    return true;
  }

  // The next read, unless the stream is finishing (no operation may follow Finish).
  void read_next(grpc::ByteBuffer* into) {
    std::lock_guard lock(mutex_);
    if (reactor_ && !finishing_) reactor_->StartRead(into);
  }

  void on_write_done(bool ok) {
    std::lock_guard lock(mutex_);
    if (const auto send_ms = outgoing_.written(); send_ms && ok)
      metrics_->sent(Transport::grpc, *send_ms);
    writing_ = false;
    writing_bytes_.Clear();
    if (!reactor_) return;
    if (status_after_write_) {
      reactor_->Finish(*status_after_write_);
      status_after_write_.reset();
      return;
    }
    if (!ok || finishing_) return;  // the stream broke: OnDone follows
    write_next();
  }

  void detach() {
    std::lock_guard lock(mutex_);
    reactor_ = nullptr;
  }

  // The session opened (or was refused) on the worker; nothing when the stream is gone meanwhile.
  void opened(SessionHub::Opened& opened) {
    std::lock_guard lock(mutex_);
    if (!reactor_ || finishing_) return;
    if (opened.refusal) {
      finishing_ = true;
      reactor_->Finish(to_status(*opened.refusal));
      record_refusal(*metrics_, Transport::grpc, *opened.refusal);
      return;
    }
    reactor_->on_opened(std::move(opened));
  }

 private:
  void write_next() {
    const auto message = outgoing_.next();
    if (!message) return;
    bool own_buffer = false;
    // Serialising cannot fail for a message this server built; gRPC would do the same copy.
    (void)grpc::SerializationTraits<v1::ServerMessage>::Serialize(*message, &writing_bytes_,
                                                                  &own_buffer);
    writing_ = true;
    reactor_->StartWrite(&writing_bytes_);
  }

  std::mutex mutex_;
  StreamReactor* reactor_;
  Metrics* metrics_;
  bool writing_ = false;
  bool finishing_ = false;
  bool hello_came_ = false;
  grpc::ByteBuffer writing_bytes_;  // kept until its write is done
  OutgoingMessages outgoing_;
  std::optional<grpc::Status> status_after_write_;
};

StreamReactor::StreamReactor(SessionHub& hub, std::string address)
    : hub_(&hub),
      sink_(std::make_shared<GrpcViewerSink>(this, hub.metrics())),
      protocol_(hub.limits(), hub.token()),
      address_(std::move(address)) {
  // The alarm's reaction holds the sink and the refusal, not the reactor: it may run after the
  // stream is done.
  hello_deadline_.Set(std::chrono::system_clock::now() + hub.limits().hello_timeout,
                      [sink = sink_, late = protocol_.no_hello()](bool fired) {
                        if (fired)
                          sink->end_unopened(late);  // else cancelled: the Hello came, or it ended
                      });
  StartRead(&incoming_);
}

void StreamReactor::refuse(const Refusal& refusal) {
  sink_->end(refusal);
  // The viewer leaves now, even if a client that stopped reading holds the last write open.
  if (viewer_) viewer_->leave(Departure::dropped);
}

void StreamReactor::OnReadDone(bool ok) {
  if (!ok) {  // the client closed its side, or the stream broke
    sink_->finish(grpc::Status::OK);
    return;
  }
  if (!viewer_) {  // the first message: whatever it is, the deadline has been met
    hello_deadline_.Cancel();
    if (!sink_->hello_came()) return;  // too late: the stream was ended, OnDone follows
  }
  // gRPC takes messages as large as a snapshot (PutSnapshot); a stream's are never that large, and
  // one is refused before it is parsed.
  if (incoming_.Length() > kMaxClientMessageBytes) {
    refuse(Refusal(RefusalCode::resource_exhausted,
                   "a Stream message of " + std::to_string(incoming_.Length()) +
                       " bytes: over the " + std::to_string(kMaxClientMessageBytes / 1024) +
                       " KiB the largest ClientMessage can be"));
    return;
  }
  try {
    auto next = [this] {
      grpc::ProtoBufferReader bytes(&incoming_);  // reads the buffer: ends before it is cleared
      return protocol_.receive(bytes);
    }();
    incoming_.Clear();
    if (auto* hello = std::get_if<StreamProtocol::Open>(&next)) {
      // The next read starts once the session is open (on_opened).
      hub_->open(std::move(hello->hello), address_, sink_,
                 [sink = sink_](SessionHub::Opened opened) {
                   sink->opened(opened);  // a stream gone meanwhile drops the link: it leaves
                 });
      return;
    }
    viewer_->post(std::move(std::get<StreamProtocol::Post>(next).message));
    sink_->read_next(&incoming_);
  } catch (const Refusal& refusal) {
    refuse(refusal);
  }
}

void StreamReactor::on_opened(SessionHub::Opened opened) {
  viewer_ = std::move(opened.viewer);
  protocol_.opened(opened.access);
  StartRead(&incoming_);
}

void StreamReactor::OnWriteDone(bool ok) { sink_->on_write_done(ok); }

void StreamReactor::OnCancel() {
  cancelled_ = true;
  sink_->finish(grpc::Status::CANCELLED);
}

void StreamReactor::OnDone() {
  sink_->detach();
  if (viewer_) viewer_->leave(cancelled_ ? Departure::dropped : Departure::left);
  delete this;
}

}  // namespace fluidcast::server
