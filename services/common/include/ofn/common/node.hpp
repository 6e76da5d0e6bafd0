#pragma once
// A node owns one service's subscriptions, timers, counters and heartbeat on
// a shared LCM handle. It never reads the wall clock for control decisions:
// all times come from the Clock it is given.

#include <algorithm>
#include <chrono>
#include <exception>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>
#include <lcm/lcm-cpp.hpp>

#include "ofn/bus_auth/authenticator.hpp"
#include "ofn/common/clock.hpp"
#include "ofn/common/link_model.hpp"
#include "ofn/common/message_caps.hpp"
#include "ofn/common/sequence_tracker.hpp"

namespace ofn {

/// Distinct rejection kinds counted one by one; the rest count as one.
constexpr size_t kMaxRejectKinds = 64;
constexpr const char* kOtherRejectKind = "(other kinds)";

/// A rejection reason with its numbers replaced by '#' ("stale by 0.73 s"
/// -> "stale by # s"): the key it is counted under.
std::string reject_kind(const std::string& reason);

/// Receipt and rejection counters reported in the heartbeat.
struct NodeCounters {
  int64_t received = 0;
  int64_t rejected = 0;
  int64_t late = 0;
  /// Of the rejected: refused by the authenticated bus (unsigned, forged,
  /// replayed, or from a role that may not publish on the channel).
  int64_t unauthenticated = 0;
  std::string last_reject_reason;
  /// By reject_kind of "channel: reason", at most kMaxRejectKinds + 1 entries.
  std::map<std::string, int64_t> rejected_by_reason;
};

/// Options for one subscription.
struct SubscribeOptions {
  /// A message whose utime is older than this (clock time) is rejected as
  /// stale and counted as late; <= 0 disables the check.
  double max_age = 0.0;
  /// A message stamped further in the future than this is rejected.
  double max_future = 1.0;
};

class Node {
 public:
  Node(std::string name, lcm::LCM& lcm, const Clock& clock);
  ~Node();
  Node(const Node&) = delete;
  Node& operator=(const Node&) = delete;

  const std::string& name() const { return name_; }
  const Clock& clock() const { return clock_; }
  lcm::LCM& lcm() { return lcm_; }
  spdlog::logger& log() { return *log_; }
  const NodeCounters& counters() const { return counters_; }
  Utime now() const { return clock_.now(); }

  /// Subscribes `handler` to `channel`. Every message is checked against
  /// the channel's size cap (ofn/common/message_caps.hpp) before anything
  /// else, decoded, counted by its publisher's sequence number (lost,
  /// duplicated: input_counts), checked by validate(Msg) (the caller
  /// includes ofn/common/validate/<message>.hpp of each type it subscribes
  /// to) and for staleness; a bad one is counted, logged (rate limited) and
  /// dropped, and the handler never sees it.
  template <class Msg>
  void subscribe(const std::string& channel, std::function<void(const Msg&)> handler,
                 SubscribeOptions options = {}) {
    auto sub = std::make_unique<Subscription>();
    sub->node = this;
    sub->channel = channel;
    sub->deliver = [this, handler = std::move(handler), options, channel,
                    cap = max_message_bytes(channel),
                    sequences = track_input(channel)](const lcm::ReceiveBuffer* rbuf) {
      // Room for the trailers: an open bus reads the sequence and ignores a
      // signature, an authenticated one requires it.
      if (rbuf->data_size > cap + bus_auth::kMaxTrailerBytes) {
        reject(channel, "oversized: " + std::to_string(rbuf->data_size) +
                            " bytes, over the channel's cap of " + std::to_string(cap));
        return;
      }
      size_t payload_size = rbuf->data_size;
      if (auth_) {
        const auto opened = auth_->open(channel, rbuf->data, rbuf->data_size);
        if (!opened.authentic) {
          ++counters_.unauthenticated;
          reject(channel, "unauthenticated: " + opened.reason);
          return;
        }
        payload_size = opened.payload_size;
      }
      Msg msg;
      bus_auth::Trailers trailers;
      // The generated decoders bound counts and lengths by the bytes left
      // (cmake/HardenLcmDecode.cmake); anything they still throw is one bad
      // message, not a reason for the service to die. Without
      // authentication a signature is ignored (a replayed authenticated log).
      if (!bus_auth::decode_payload(msg, rbuf->data, payload_size, &trailers)) {
        reject(channel, "undecodable (" + std::to_string(rbuf->data_size) + " bytes)");
        return;
      }
      // Counted whatever validation says of the content: the number says
      // whether the link lost, copied or reordered it.
      if (sequences) {
        if (trailers.sequenced)
          sequences->on_sequenced(trailers.sequence.publisher, trailers.sequence.sequence);
        else
          sequences->on_unsequenced();
      }
      if (std::string why = validate(msg); !why.empty()) {
        reject(channel, why);
        return;
      }
      if (!check_time(channel, msg.utime, options)) return;
      ++counters_.received;
      handler(msg);
    };
    add_subscription(std::move(sub));
  }

  /// Publishes `msg` with its sequence trailer (this node's publisher id
  /// and the channel's next number, from 1); on an authenticated bus
  /// signed, with the authentication trailer after it.
  template <class Msg>
  void publish(const std::string& channel, const Msg& msg) {
    if (link_) link_->published(name_, channel);
    const int size = msg.getEncodedSize();
    publish_buffer_.resize(static_cast<size_t>(std::max(size, 0)));
    if (size < 0 || msg.encode(publish_buffer_.data(), 0, size) != size)
      throw std::runtime_error(channel + ": message could not be encoded");
    bus_auth::append_sequence_trailer(publish_buffer_, {publisher_id_, ++published_[channel]});
    if (auth_) auth_->seal(channel, publish_buffer_);
    lcm_.publish(channel, publish_buffer_.data(),
                 static_cast<unsigned int>(publish_buffer_.size()));
  }

  /// The id this node's messages carry in their sequence trailer: random
  /// per process, mixed with the node's name and the order nodes were made
  /// in, so that a restarted service is a new publisher. Under a
  /// deterministic clock (lockstep) derived from the name, the clock's time
  /// when the node was made and that order alone, so runs repeat to the bit.
  uint64_t publisher_id() const { return publisher_id_; }

  /// Per channel subscribed to: what its publishers' sequence numbers say
  /// (received, lost, duplicated, unsequenced, publishers), as the heartbeat
  /// reports it.
  std::map<std::string, SequenceCounts> input_counts() const;

  /// True when this node signs and checks every message (--bus-keys).
  bool authenticated() const { return auth_ != nullptr; }

  /// Calls `callback` every `period` seconds of the clock's timer time
  /// (Clock::timer_now: clock time, but monotonic time for the wall
  /// clock), first at the first tick that is a whole multiple of the period.
  void add_timer(double period, std::function<void()> callback, std::string label);

  /// Earliest timer deadline, or arrival of a message a simulated link
  /// holds back (timer time); INT64_MAX when there is none.
  Utime next_deadline() const;
  /// Hands over the messages a simulated link held back until the clock's
  /// timer time, then runs every timer due at or before it. Catch-up is
  /// bounded under every clock: a timer that fell behind (a stopped or
  /// starved process, a clock that jumped ahead) fires once and keeps to
  /// its period from then on, the periods it missed counted, never run; one
  /// whose clock went back starts on its period afresh, as at start.
  void fire_due_timers();
  /// Schedules every timer afresh from the next clock tick, as at start: for
  /// a clock that was deliberately set to another timeline (a restarted
  /// simulation), where the old deadlines mean nothing.
  void restart_timers();

  /// Counts and logs a rejected input; for checks a service makes itself.
  void reject(const std::string& channel, const std::string& reason);
  /// Service state reported in the heartbeat ("starting", "running", "degraded").
  void set_state(std::string state) { state_ = std::move(state); }

 private:
  struct Subscription {
    Node* node = nullptr;
    std::string channel;
    std::function<void(const lcm::ReceiveBuffer*)> deliver;
    lcm::Subscription* handle = nullptr;
  };
  struct Timer {
    double period;
    Utime period_us;
    Utime deadline;  // timer time; INT64_MIN until scheduled from the first valid clock
    std::function<void()> callback;
    std::string label;
    int64_t overruns = 0;  // periods missed, not run
  };

  // A message a simulated link delays: for whom, and its bytes.
  struct HeldMessage {
    Subscription* sub;
    std::vector<uint8_t> bytes;
  };

  static void on_raw(const lcm::ReceiveBuffer* rbuf, const std::string& channel, Subscription* sub);
  /// Hands `rbuf` to the subscription, counting the time it takes as work.
  void deliver_now(Subscription* sub, const lcm::ReceiveBuffer* rbuf);
  void deliver_held(Utime now);
  void add_subscription(std::unique_ptr<Subscription> sub);
  /// The sequence counter of a channel's first subscription; nullptr for a
  /// second one on the same channel (a message is counted once).
  SequenceTracker* track_input(const std::string& channel);
  bool check_time(const std::string& channel, Utime stamp, const SubscribeOptions& options);
  void publish_heartbeat();
  void account_work(std::chrono::steady_clock::duration busy);

  std::string name_;
  lcm::LCM& lcm_;
  const Clock& clock_;
  std::shared_ptr<bus_auth::Authenticator> auth_;
  std::shared_ptr<LinkModel> link_;
  std::multimap<Utime, HeldMessage> held_;  // by due timer time, then arrival
  std::vector<uint8_t> publish_buffer_;
  uint64_t publisher_id_ = 0;
  std::map<std::string, uint64_t> published_;         // last sequence number per channel
  std::map<std::string, SequenceTracker> sequences_;  // per channel subscribed to
  std::shared_ptr<spdlog::logger> log_;
  std::vector<std::unique_ptr<Subscription>> subscriptions_;
  std::vector<Timer> timers_;
  NodeCounters counters_;
  std::string state_ = "starting";
  Utime start_time_ = INT64_MIN;  // timer time of the first firing

  // Work statistics over the current heartbeat period (wall time: it
  // measures CPU cost, it does not drive behaviour).
  int64_t work_calls_ = 0;
  double work_total_ = 0.0;
  double work_max_ = 0.0;
  std::chrono::steady_clock::time_point period_start_;
  // Rate limit for rejection log lines (timer time).
  Utime last_reject_log_ = INT64_MIN;
  int64_t suppressed_rejects_ = 0;
};

/// Makes every Node made on `lcm` from now on sign what it publishes and
/// accept only what `authenticator` finds authentic (an authenticated bus,
/// docs/DEPLOYMENT.md). open_lcm() does this for --bus-keys; detach before
/// the handle is destroyed (open_lcm's handle does it itself).
void attach_authenticator(lcm::LCM& lcm, std::shared_ptr<bus_auth::Authenticator> authenticator);
void detach_authenticator(lcm::LCM& lcm);

/// Makes every Node made on `lcm` from now on send and receive through
/// `link` (a simulated network, ofn/common/link_model.hpp); detach before
/// the handle is destroyed.
void attach_link_model(lcm::LCM& lcm, std::shared_ptr<LinkModel> link);
void detach_link_model(lcm::LCM& lcm);

/// Heartbeat channel of a service: HEARTBEAT_<NAME>.
std::string heartbeat_channel(const std::string& service);

}  // namespace ofn
