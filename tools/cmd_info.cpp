// `romo info FILE.lcmlog [--json]`: channels, counts, rates, span, gaps and drops of a recording.
#include <algorithm>
#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/command_registry.hpp"
#include "romo/core/json.hpp"
#include "romo/drivers/recording.hpp"
#include "romo_lcm/ground_truth_t.hpp"
#include "romo_lcm/gt_depth_t.hpp"
#include "romo_lcm/manip_result_t.hpp"
#include "romo_lcm/obstacle_list_t.hpp"
#include "romo_lcm/parking_slots_t.hpp"
#include "romo_lcm/pedestrian_predictions_t.hpp"
#include "romo_lcm/perception_status_t.hpp"
#include "romo_lcm/rig_cloud_t.hpp"

namespace romo::tools {
namespace {

// How many of the largest inter-event gaps to list per channel.
constexpr std::size_t kGapsShown = 3;

struct ChannelStats {
  std::string type;
  std::uint64_t count = 0;
  std::uint64_t bytes = 0;
  std::int64_t first_us = 0;
  std::int64_t last_us = 0;
  std::vector<std::int64_t> largest_gaps_us;  // descending, at most kGapsShown
  std::uint64_t dropped = 0;                  // frame_sequence gaps
  std::optional<std::uint64_t> last_sequence;

  double span_s() const { return static_cast<double>(last_us - first_us) * 1e-6; }
  double rate_hz() const { return count > 1 && last_us > first_us ? (count - 1) / span_s() : 0.0; }
};

// The drivers know the sensor types; the outputs, ground truth and worker clouds a run or a
// simulation writes into the same logs are named here, where they are listed.
void RegisterOutputTypes() {
  drivers::RegisterLcmType(romo_lcm::ground_truth_t::getHash(), "romo_lcm.ground_truth_t");
  drivers::RegisterLcmType(romo_lcm::gt_depth_t::getHash(), "romo_lcm.gt_depth_t");
  drivers::RegisterLcmType(romo_lcm::manip_result_t::getHash(), "romo_lcm.manip_result_t");
  drivers::RegisterLcmType(romo_lcm::obstacle_list_t::getHash(), "romo_lcm.obstacle_list_t");
  drivers::RegisterLcmType(romo_lcm::parking_slots_t::getHash(), "romo_lcm.parking_slots_t");
  drivers::RegisterLcmType(romo_lcm::pedestrian_predictions_t::getHash(), "romo_lcm.pedestrian_predictions_t");
  drivers::RegisterLcmType(romo_lcm::perception_status_t::getHash(), "romo_lcm.perception_status_t");
  drivers::RegisterLcmType(romo_lcm::rig_cloud_t::getHash(), "romo_lcm.rig_cloud_t");
}

void Info(const std::string& path, bool json) {
  RegisterOutputTypes();
  std::map<std::string, ChannelStats> channels;
  std::int64_t first_us = 0;
  std::int64_t last_us = 0;
  std::uint64_t events = 0;
  std::uint64_t bytes = 0;
  const std::int64_t cut = drivers::ScanEvents(path, [&](const drivers::LogEvent& event) {
    if (events == 0) first_us = event.timestamp_us;
    first_us = std::min(first_us, event.timestamp_us);
    last_us = std::max(last_us, event.timestamp_us);
    ++events;
    bytes += event.data.size();
    ChannelStats& c = channels[event.channel];
    if (c.count == 0) {
      c.type = drivers::LcmTypeName(event.data.data(), event.data.size());
      c.first_us = event.timestamp_us;
    } else {
      c.largest_gaps_us.push_back(event.timestamp_us - c.last_us);
      std::sort(c.largest_gaps_us.rbegin(), c.largest_gaps_us.rend());
      if (c.largest_gaps_us.size() > kGapsShown) c.largest_gaps_us.resize(kGapsShown);
    }
    c.last_us = event.timestamp_us;
    ++c.count;
    c.bytes += event.data.size();
    if (const auto sequence = drivers::FrameSequenceOf(event)) {
      if (c.last_sequence && *sequence > *c.last_sequence + 1) {
        c.dropped += *sequence - *c.last_sequence - 1;
      }
      c.last_sequence = sequence;
    }
  });
  const double span_s = events > 0 ? static_cast<double>(last_us - first_us) * 1e-6 : 0.0;

  if (json) {
    std::printf("{\"file\":%s,\"span_s\":%.6f,\"events\":%llu,\"bytes\":%llu,\"channels\":[",
                JsonString(path).c_str(), span_s, static_cast<unsigned long long>(events),
                static_cast<unsigned long long>(bytes));
    bool first = true;
    for (const auto& [name, c] : channels) {
      std::printf("%s{\"name\":%s,\"type\":%s,\"count\":%llu,\"rate_hz\":%.6f,\"bytes\":%llu,"
                  "\"dropped\":%llu,\"largest_gaps_s\":[",
                  first ? "" : ",", JsonString(name).c_str(), JsonString(c.type).c_str(),
                  static_cast<unsigned long long>(c.count), c.rate_hz(),
                  static_cast<unsigned long long>(c.bytes),
                  static_cast<unsigned long long>(c.dropped));
      for (std::size_t i = 0; i < c.largest_gaps_us.size(); ++i) {
        std::printf("%s%.6f", i ? "," : "", static_cast<double>(c.largest_gaps_us[i]) * 1e-6);
      }
      std::printf("]}");
      first = false;
    }
    std::printf("],\"truncated\":%s,\"truncated_at\":%lld}\n", cut >= 0 ? "true" : "false",
                static_cast<long long>(cut));
    return;
  }

  std::printf("file      %s\n", path.c_str());
  std::printf("events    %llu (%.1f MB), span %.3f s\n", static_cast<unsigned long long>(events),
              static_cast<double>(bytes) / 1e6, span_s);
  if (cut >= 0) {
    std::printf("TRUNCATED at byte %lld: every complete event before it is counted\n",
                static_cast<long long>(cut));
  }
  std::printf("%-24s %-28s %8s %9s %8s %s\n", "channel", "type", "count", "rate_hz", "dropped",
              "largest gaps (s)");
  for (const auto& [name, c] : channels) {
    std::string gaps;
    for (const auto gap : c.largest_gaps_us) {
      char text[32];
      std::snprintf(text, sizeof text, "%s%.3f", gaps.empty() ? "" : " ", gap * 1e-6);
      gaps += text;
    }
    std::printf("%-24s %-28s %8llu %9.2f %8llu %s\n", name.c_str(), c.type.c_str(),
                static_cast<unsigned long long>(c.count), c.rate_hz(),
                static_cast<unsigned long long>(c.dropped), gaps.c_str());
  }
}

void Register(CLI::App& root) {
  auto path = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  auto* command = root.add_subcommand(
      "info", "Summarise a recording: channels, types, counts, rates, span, gaps, drops");
  command->add_option("file", *path, "LCM log file")->required();
  command->add_flag("--json", *json, "Print JSON");
  command->callback([path, json] { Info(*path, *json); });
}

ROMO_REGISTER_COMMAND(Register);

}  // namespace
}  // namespace romo::tools
