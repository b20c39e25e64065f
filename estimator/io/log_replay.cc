#include "estimator/io/log_replay.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <deque>
#include <map>
#include <optional>
#include <set>
#include <utility>

#include "core/config/config.h"
#include "core/log/mcap/mcap_reader.h"
#include "core/log/msgs/message_traits.h"
#include "estimator/eskf/local_reference_filter.h"
#include "estimator/io/estimator_log_records.h"

namespace rover::estimator::io {
namespace {

namespace msgs = log::rover_msgs;

// Collects what the replayed filter produces, tagged with the input sequence.
class CollectingSink final : public EskfOutputSink {
 public:
  void OnState(const EskfOutput& output) override { states.push_back(ToMsg(output, sequence)); }
  void OnFrameSwitch(const FrameSwitchRecord& record) override {
    switches.push_back(ToMsg(record, sequence));
  }
  void OnPoseReport(const PoseReport&) override {}
  void OnReject(const RejectRecord&) override {}

  uint64_t sequence = 0;
  std::deque<msgs::EstimatorState> states;
  std::deque<msgs::EstimatorFrameSwitch> switches;
};

std::string Number(double v) {
  char text[40];
  std::snprintf(text, sizeof(text), "%.17g", v);
  return text;
}

// Names the first field that differs between two states (bitwise).
template <std::size_t N>
bool DiffArray(const char* name, const std::array<double, N>& a, const std::array<double, N>& b,
               std::string* out) {
  for (std::size_t i = 0; i < N; ++i) {
    if (std::memcmp(&a[i], &b[i], sizeof(double)) != 0) {
      *out = std::string(name) + "[" + std::to_string(i) + "]: logged " + Number(a[i]) +
             ", replayed " + Number(b[i]);
      return true;
    }
  }
  return false;
}

std::string DescribeDifference(const msgs::EstimatorState& a, const msgs::EstimatorState& b) {
  std::string d;
  if (a.stamp_ns != b.stamp_ns)
    return "stamp_ns: logged " + std::to_string(a.stamp_ns) + ", replayed " +
           std::to_string(b.stamp_ns);
  if (a.frame_id != b.frame_id) return "frame_id differs";
  if (a.status != b.status) {
    return "status: logged " + std::to_string(a.status) + ", replayed " + std::to_string(b.status);
  }
  if (DiffArray("p_local_body_m", a.p_local_body_m, b.p_local_body_m, &d) ||
      DiffArray("v_local_m_s", a.v_local_m_s, b.v_local_m_s, &d) ||
      DiffArray("q_local_body_xyzw", a.q_local_body_xyzw, b.q_local_body_xyzw, &d) ||
      DiffArray("accel_bias_m_s2", a.accel_bias_m_s2, b.accel_bias_m_s2, &d) ||
      DiffArray("gyro_bias_rad_s", a.gyro_bias_rad_s, b.gyro_bias_rad_s, &d) ||
      DiffArray("angular_velocity_body_rad_s", a.angular_velocity_body_rad_s,
                b.angular_velocity_body_rad_s, &d) ||
      DiffArray("covariance", a.covariance, b.covariance, &d)) {
    return d;
  }
  return "sequence differs";
}

template <typename Msg>
bool SameBytes(const Msg& a, const Msg& b) {
  return log::SerializeMessage(a) == log::SerializeMessage(b);
}

// The logged inputs, keyed by sequence.
struct LoggedInputs {
  std::map<uint64_t, EskfInput> by_sequence;
  std::string problem;
};

template <typename Msg>
std::optional<Msg> Decode(const log::MessageView& m, const std::string& topic,
                          std::string* problem) {
  Msg msg;
  std::string error;
  if (!log::DeserializeMessage(m.data, &msg, &error)) {
    if (problem->empty()) {
      *problem = "undecodable record on " + topic + " at log time " + std::to_string(m.log_time) +
                 ": " + error;
    }
    return std::nullopt;
  }
  return msg;
}

}  // namespace

ReplayResult ReplayLog(const std::string& path,
                       const std::function<void(double fraction)>& progress) {
  ReplayResult result;
  log::McapReader reader = log::McapReader::Open(path);
  // Options.
  std::optional<EskfOptions> options;
  for (const log::Metadata& m : reader.metadata()) {
    if (m.name != kOptionsMetadata) continue;
    const auto it = m.metadata.find("yaml");
    if (it != m.metadata.end()) {
      options = EskfOptions::Load(ConfigNode::LoadString(it->second, path + " metadata"));
    }
  }
  if (!options) {
    result.first_difference = std::string("no '") + kOptionsMetadata +
                              "' metadata record: the log does not say how the filter was set up";
    return result;
  }
  std::map<uint16_t, std::string> topic_of;
  for (const auto& [id, channel] : reader.channels()) topic_of[id] = channel.topic;

  // Pass 1: the inputs.
  LoggedInputs inputs;
  reader.ForEachMessage([&](const log::MessageView& m) {
    const std::string& topic = topic_of[m.channel_id];
    std::string* problem = &inputs.problem;
    if (topic == kImuInputTopic) {
      if (auto r = Decode<msgs::EstimatorImu>(m, topic, problem)) {
        inputs.by_sequence.emplace(r->sequence, EskfInput(FromMsg(*r)));
      }
    } else if (topic == kRelativePoseInputTopic) {
      if (auto r = Decode<msgs::EstimatorRelativePose>(m, topic, problem)) {
        inputs.by_sequence.emplace(r->sequence, EskfInput(FromMsg(*r)));
      }
    } else if (topic == kWheelSpeedsInputTopic) {
      if (auto r = Decode<msgs::EstimatorWheelSpeeds>(m, topic, problem)) {
        inputs.by_sequence.emplace(r->sequence, EskfInput(FromMsg(*r)));
      }
    } else if (topic == kEventInputTopic) {
      if (auto r = Decode<msgs::EstimatorEvent>(m, topic, problem)) {
        if (auto in = FromMsg(*r)) {
          inputs.by_sequence.emplace(r->sequence, *in);
        } else if (problem->empty()) {
          *problem = "unknown event kind " + std::to_string(r->kind) + " at sequence " +
                     std::to_string(r->sequence);
        }
      }
    }
    return true;
  });
  if (!inputs.problem.empty()) {
    result.first_difference = inputs.problem;
    return result;
  }
  uint64_t expected = 0;
  for (const auto& [sequence, input] : inputs.by_sequence) {
    if (sequence != expected) {
      result.first_difference = "input sequence " + std::to_string(expected) +
                                " is missing from the log (inputs " + std::to_string(expected) +
                                ".." + std::to_string(sequence - 1) +
                                " dropped?): the replay cannot be exact";
      return result;
    }
    ++expected;
  }

  // Pass 2: feed inputs up to each logged output's sequence and compare.
  CollectingSink sink;
  LocalReferenceFilter filter(*options, &sink);
  auto next_input = inputs.by_sequence.begin();
  const auto feed_through = [&](uint64_t sequence) {
    while (next_input != inputs.by_sequence.end() && next_input->first <= sequence) {
      sink.sequence = next_input->first;
      filter.Process(next_input->second);
      ++next_input;
      ++result.inputs;
      if (progress && result.inputs % 20000 == 0) {
        progress(static_cast<double>(result.inputs) /
                 static_cast<double>(inputs.by_sequence.size()));
      }
    }
  };
  std::string difference;
  reader.ForEachMessage([&](const log::MessageView& m) {
    const std::string& topic = topic_of[m.channel_id];
    if (topic == kStateTopic) {
      const auto logged = Decode<msgs::EstimatorState>(m, topic, &difference);
      if (!logged) return false;
      feed_through(logged->sequence);
      while (!sink.states.empty() && sink.states.front().sequence < logged->sequence) {
        sink.states.pop_front();
        ++result.unlogged_outputs;
      }
      if (sink.states.empty() || sink.states.front().sequence != logged->sequence) {
        difference = "state logged after input " + std::to_string(logged->sequence) + " (stamp " +
                     std::to_string(logged->stamp_ns) + " ns) was not produced by the replay";
        return false;
      }
      const msgs::EstimatorState replayed = sink.states.front();
      sink.states.pop_front();
      if (!SameBytes(*logged, replayed)) {
        difference = "state #" + std::to_string(result.states_compared) + " (input " +
                     std::to_string(logged->sequence) + ", stamp " +
                     std::to_string(logged->stamp_ns) +
                     " ns) differs: " + DescribeDifference(*logged, replayed);
        return false;
      }
      ++result.states_compared;
    } else if (topic == kFrameSwitchRecordTopic) {
      const auto logged = Decode<msgs::EstimatorFrameSwitch>(m, topic, &difference);
      if (!logged) return false;
      feed_through(logged->sequence);
      while (!sink.switches.empty() && sink.switches.front().sequence < logged->sequence) {
        sink.switches.pop_front();
        ++result.unlogged_outputs;
      }
      if (sink.switches.empty() || !SameBytes(*logged, sink.switches.front())) {
        difference = "frame switch record after input " + std::to_string(logged->sequence) +
                     " differs from the replay";
        return false;
      }
      sink.switches.pop_front();
      ++result.switches_compared;
    }
    return true;
  });
  if (!difference.empty()) {
    result.first_difference = difference;
    return result;
  }
  feed_through(UINT64_MAX);
  if (result.unlogged_outputs > 0) {
    result.notes.push_back(std::to_string(result.unlogged_outputs) +
                           " replayed outputs have no logged counterpart (dropped by the log)");
  }
  if (result.states_compared == 0) {
    result.first_difference = "the log holds no estimator states to compare";
    return result;
  }
  result.bit_exact = true;
  return result;
}

}  // namespace rover::estimator::io
