#include "romo/core/json.hpp"
#include "romo/pipeline/outputs.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "romo/core/check.hpp"
#include "romo/objects/prediction_log.hpp"
#include "romo/planning_iface/lcm_bus.hpp"
#include "romo/sim/ground_truth.hpp"
#include "romo/viz/top_view.hpp"

namespace romo::pipeline {
namespace fs = std::filesystem;
namespace pi = planning_iface;

std::vector<std::string> OutputChannels() {
  return {pi::kObstaclesChannel, pi::kParkingSlotsChannel, pi::kPerceptionStatusChannel,
          objects::kPedestrianPredictionChannel};
}

class OutputSink::Impl {
 public:
  OutputOptions options;
  std::unique_ptr<drivers::LogWriter> log;
  std::unique_ptr<objects::PredictionCsvWriter> csv;
  std::unique_ptr<pi::LcmBus> bus;
  viz::TopViewParams view;
  std::int64_t frames = 0;
  bool finished = false;

  // Summary state.
  struct StageSummary {
    std::optional<FrameResult> last;
    std::vector<viz::TruthOutline> last_truth;
    std::vector<Eigen::Vector2d> trail;
    std::int64_t first_seq = -1, last_seq = -1, frames = 0;
  };
  std::map<pi::ManeuverStage, StageSummary> stages;
  std::map<std::string, double> stage_ms_sum;
  std::vector<std::string> stage_order;
  double total_ms_sum = 0;
  std::int64_t missing_rig_frames = 0;
  std::int64_t max_tracks = 0;
  // Distinct tracks and pedestrian tracks so far, counted as they first appear. The sets hold
  // only the tracks alive now: a track is listed in every frame from its creation to its end and
  // its id is never given again, so what a run of hours remembers does not grow with it.
  std::set<int> live_track_ids, live_pedestrian_ids;
  std::int64_t tracks_total = 0, pedestrian_tracks = 0;
  void CountTracks(const FrameResult& r) {
    std::set<int> live, pedestrians;
    for (const auto& t : r.tracks) {
      live.insert(t.id);
      tracks_total += live_track_ids.count(t.id) == 0;
      if (live_pedestrian_ids.count(t.id)) pedestrians.insert(t.id);  // predicted before: still one
    }
    for (const auto& p : r.predictions) pedestrian_tracks += pedestrians.insert(p.track_id).second;
    live_track_ids = std::move(live);
    live_pedestrian_ids = std::move(pedestrians);
  }
  // The ego's path through a stage, for its picture: every other point dropped when it reaches
  // kMaxTrailPoints (a picture is ~1000 px across), so a long run keeps a bounded path.
  static constexpr std::size_t kMaxTrailPoints = 4096;
  static void ExtendTrail(std::vector<Eigen::Vector2d>* trail, const Eigen::Vector2d& xy) {
    if (trail->size() >= kMaxTrailPoints) {
      std::size_t kept = 0;
      for (std::size_t k = 0; k < trail->size(); k += 2) (*trail)[kept++] = (*trail)[k];
      trail->resize(kept);
    }
    trail->push_back(xy);
  }
  std::vector<std::string> events;
  std::optional<pi::ParkingSlot> best_slot;
  std::int64_t frames_with_feasible_slot = 0;
  std::int64_t dropped = 0, malformed = 0;

  // The calibration goes first into the log, stamped like the first event after it (not 0), so
  // the log's span and seek offsets start at the first frame.
  std::optional<drivers::Calibration> calibration_to_log;
  void LogCalibrationOnce(std::int64_t stamp_ns) {
    if (!log || !calibration_to_log) return;
    log->WriteCalibration(*calibration_to_log, stamp_ns);
    calibration_to_log.reset();
  }

  // One output message into the log and onto the bus (each when open).
  void Emit(const std::string& channel, std::int64_t stamp_ns, const std::vector<std::uint8_t>& bytes) {
    LogCalibrationOnce(stamp_ns);
    if (log) log->WriteRaw(channel, stamp_ns, bytes.data(), bytes.size());
    if (bus) bus->Publish(channel, bytes);
  }

  // The true footprints in a passed-through ground-truth message (a simulated run, or a recording
  // of one), for the pictures. An unreadable one is reported once and the pictures go without:
  // they are a view, and the frame's outputs must still be written.
  bool truth_unreadable_reported = false;
  std::vector<viz::TruthOutline> TruthOutlines(const std::vector<drivers::LogEvent>& passthrough) {
    std::vector<viz::TruthOutline> outlines;
    for (const auto& e : passthrough) {
      if (e.channel != sim::kGroundTruthChannel) continue;
      try {
        const sim::GroundTruth truth = sim::DecodeGroundTruth(e.data.data(), e.data.size(), e.channel);
        for (const auto& o : truth.objects) outlines.push_back({o.class_name, o.Footprint()});
      } catch (const std::exception& err) {
        if (!truth_unreadable_reported) {
          const std::string what = std::string("pictures drawn without ground truth: ") + err.what();
          std::fprintf(stderr, "romo: %s\n", what.c_str());
          events.push_back(what);
          truth_unreadable_reported = true;
        }
      }
    }
    return outlines;
  }

  void RecordStatus(const pi::PerceptionStatus& status) {
    for (const auto& e : status.events) {
      if (events.size() < 200) events.push_back("frame " + std::to_string(status.frame_sequence) + ": " + e);
    }
    dropped = status.frames_dropped;
    malformed = status.malformed_messages;
  }
};

OutputSink::OutputSink(const drivers::Calibration& calibration, const OutputOptions& options)
    : impl_(std::make_unique<Impl>()) {
  impl_->options = options;
  impl_->view.size_px = options.picture_size_px;
  impl_->view.span_m = options.picture_span_m;
  impl_->view.Validate();
  if (!options.out_dir.empty()) {
    std::error_code ec;
    fs::create_directories(fs::path(options.out_dir) / "frames", ec);
    if (ec) Fail("outputs: cannot create folder " + options.out_dir + ": " + ec.message());
    impl_->log = std::make_unique<drivers::LogWriter>(options.out_dir + "/outputs.lcmlog");
    impl_->calibration_to_log = calibration;
    impl_->csv = std::make_unique<objects::PredictionCsvWriter>(options.out_dir + "/predictions.csv");
    for (const std::string& kept : {impl_->log->kept_interrupted(), impl_->csv->kept_interrupted()}) {
      if (!kept.empty()) std::fprintf(stderr, "romo: an interrupted run's output was kept as %s\n", kept.c_str());
    }
  }
  if (!options.lcm_url.empty()) impl_->bus = std::make_unique<pi::LcmBus>(options.lcm_url);
}

OutputSink::~OutputSink() {
  try {
    Finish();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "romo: outputs: %s\n", e.what());
  }
}

std::int64_t OutputSink::frames_written() const { return impl_->frames; }

std::string OutputSink::log_path() const {
  return impl_->options.out_dir.empty() ? "" : impl_->options.out_dir + "/outputs.lcmlog";
}

void OutputSink::Write(const drivers::FrameSet* inputs, const FrameResult& r,
                       const std::vector<drivers::LogEvent>& passthrough) {
  Impl& s = *impl_;
  const std::vector<std::pair<std::string, std::vector<std::uint8_t>>> messages = {
      {pi::kObstaclesChannel, pi::Encode(r.obstacles)},
      {pi::kParkingSlotsChannel, pi::Encode(r.slots)},
      {pi::kPerceptionStatusChannel, pi::Encode(r.status)},
      {objects::kPedestrianPredictionChannel,
       objects::EncodePedestrianPredictions(r.stamp_ns, r.frame_sequence, r.predictions)}};
  if (s.log) {
    s.LogCalibrationOnce(r.stamp_ns);
    if (inputs != nullptr && s.options.log_inputs) s.log->Write(*inputs);
    for (const auto& e : passthrough) {
      s.log->WriteRaw(e.channel, r.stamp_ns, e.data.data(), e.data.size());
    }
  }
  for (const auto& [channel, bytes] : messages) s.Emit(channel, r.stamp_ns, bytes);
  if (s.csv) s.csv->WriteFrame(r.predictions);
  // The truth is drawn in this frame's picture and, if it ends its stage, in the stage picture.
  const bool writes_files = !s.options.out_dir.empty();
  std::vector<viz::TruthOutline> truth = writes_files ? s.TruthOutlines(passthrough) : std::vector<viz::TruthOutline>{};
  if (writes_files && s.options.frame_pictures) {
    char name[64];
    std::snprintf(name, sizeof(name), "/frames/frame_%06lld.png", static_cast<long long>(r.frame_sequence));
    viz::WritePng(s.options.out_dir + name, viz::DrawTopView(r, s.view, {}, "", truth));
  }

  // Summary bookkeeping.
  ++s.frames;
  for (const auto& st : r.status.stages) {
    if (!s.stage_ms_sum.count(st.name)) s.stage_order.push_back(st.name);
    s.stage_ms_sum[st.name] += st.latency_ms;
  }
  s.total_ms_sum += r.status.total_latency_ms;
  if (!r.missing_rigs.empty()) ++s.missing_rig_frames;
  s.max_tracks = std::max<std::int64_t>(s.max_tracks, static_cast<std::int64_t>(r.tracks.size()));
  s.CountTracks(r);
  s.RecordStatus(r.status);
  bool feasible = false;
  for (const auto& slot : r.slots.slots) {
    if (slot.feasible) {
      feasible = true;
      if (!s.best_slot || slot.confidence >= s.best_slot->confidence) s.best_slot = slot;
    }
  }
  if (feasible) ++s.frames_with_feasible_slot;
  const pi::ManeuverStage stage = r.slots.stage;
  if (stage == pi::ManeuverStage::kApproach || stage == pi::ManeuverStage::kTurn ||
      stage == pi::ManeuverStage::kSideways) {
    auto& sum = s.stages[stage];
    if (sum.first_seq < 0) sum.first_seq = r.frame_sequence;
    sum.last_seq = r.frame_sequence;
    ++sum.frames;
    Impl::ExtendTrail(&sum.trail, r.ego_world.position_m);
    sum.last = r;
    sum.last_truth = std::move(truth);
  }
}

void OutputSink::WriteStatus(const pi::PerceptionStatus& status) {
  Impl& s = *impl_;
  s.Emit(pi::kPerceptionStatusChannel, status.stamp_ns, pi::Encode(status));
  s.RecordStatus(status);
}

void OutputSink::Finish(const std::string& extra_json) {
  Impl& s = *impl_;
  if (s.finished) return;
  s.finished = true;
  s.LogCalibrationOnce(0);  // a run without any frame still says what it ran on
  if (s.log) s.log->Close();
  if (s.csv) s.csv->Close();
  if (s.options.out_dir.empty()) return;

  std::ostringstream stages_json;
  bool first = true;
  for (const auto& [stage, sum] : s.stages) {
    const std::string name = pi::ToString(stage);
    const std::string file = "stage_" + name + ".png";
    char title[96];
    std::snprintf(title, sizeof(title), "[%s: frames %lld-%lld]", name.c_str(),
                  static_cast<long long>(sum.first_seq), static_cast<long long>(sum.last_seq));
    viz::WritePng(s.options.out_dir + "/" + file, viz::DrawTopView(*sum.last, s.view, sum.trail, title, sum.last_truth));
    stages_json << (first ? "" : ",") << "\"" << name << "\":{\"frames\":" << sum.frames
                << ",\"first_frame\":" << sum.first_seq << ",\"last_frame\":" << sum.last_seq
                << ",\"picture\":\"" << file << "\"}";
    first = false;
  }

  std::ostringstream js;
  js.setf(std::ios::fixed);
  js.precision(3);
  js << "{\n  \"frames\": " << s.frames << ",\n  \"frames_dropped\": " << s.dropped
     << ",\n  \"malformed_messages\": " << s.malformed
     << ",\n  \"frames_with_missing_rigs\": " << s.missing_rig_frames << ",\n  \"latency_ms_mean\": {";
  for (std::size_t i = 0; i < s.stage_order.size(); ++i) {
    js << (i ? ", " : "") << "\"" << s.stage_order[i]
       << "\": " << (s.frames ? s.stage_ms_sum[s.stage_order[i]] / s.frames : 0.0);
  }
  js << (s.stage_order.empty() ? "" : ", ") << "\"total\": " << (s.frames ? s.total_ms_sum / s.frames : 0.0)
     << "},\n  \"tracks_total\": " << s.tracks_total << ",\n  \"pedestrian_tracks\": "
     << s.pedestrian_tracks << ",\n  \"frames_with_feasible_slot\": " << s.frames_with_feasible_slot
     << ",\n  \"best_slot\": ";
  if (s.best_slot) {
    const auto& b = *s.best_slot;
    js << "{\"id\": " << b.slot_id << ", \"center_world_m\": [" << b.target.position_m.x() << ", "
       << b.target.position_m.y() << "], \"yaw_world_rad\": " << b.target.yaw_rad
       << ", \"length_m\": " << b.length_m << ", \"depth_m\": " << b.depth_m
       << ", \"confidence\": " << b.confidence << ", \"approach_world_m\": [" << b.approach.position_m.x()
       << ", " << b.approach.position_m.y() << "], \"clearance_prev_m\": " << b.clearance_prev_m
       << ", \"clearance_next_m\": " << b.clearance_next_m << "}";
  } else {
    js << "null";
  }
  js << ",\n  \"stages\": {" << stages_json.str() << "},\n  \"events\": [";
  for (std::size_t i = 0; i < s.events.size(); ++i) {
    js << (i ? ", " : "") << "\"" << JsonEscape(s.events[i]) << "\"";
  }
  js << "],\n  \"files\": {\"log\": \"outputs.lcmlog\", \"predictions\": \"predictions.csv\", \"frames\": \"frames/\"}";
  if (!extra_json.empty()) js << ",\n  " << extra_json;
  js << "\n}\n";
  const std::string path = s.options.out_dir + "/summary.json";
  std::ofstream f(path + ".partial");
  f << js.str();
  f.close();
  if (!f) Fail("outputs: cannot write " + path);
  fs::rename(path + ".partial", path);
}

}  // namespace romo::pipeline
