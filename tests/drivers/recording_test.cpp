// Crash safety and format compatibility of recordings, across processes.
#include <csignal>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include "romo/core/check.hpp"
#include "romo/drivers/recording.hpp"
#include "test_support.hpp"

namespace romo::drivers {
namespace {

constexpr std::int64_t kStartNs = 1'700'000'000'000'000'000;
constexpr int kEventsBeforeKill = 50;
constexpr std::size_t kPayloadBytes = 64 * 1024;  // big enough that a kill often lands mid-write

std::vector<std::uint8_t> Payload(int k) {
  std::vector<std::uint8_t> data(kPayloadBytes);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<std::uint8_t>(i * 7 + k);
  return data;
}

TEST(RecordingTest, KillDashNineKeepsEveryCompletedEvent) {
  test::ScratchDir dir;
  const std::string path = dir / "killed.lcmlog";
  int pipe_fds[2];
  ASSERT_EQ(::pipe(pipe_fds), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    // The writer process: writes forever, reporting each completed event to the parent.
    ::close(pipe_fds[0]);
    LogWriter writer(path);
    for (int k = 0;; ++k) {
      const auto data = Payload(k);
      writer.WriteRaw("DATA", kStartNs + k * 1000, data.data(), data.size());
      const char done = 1;
      if (::write(pipe_fds[1], &done, 1) != 1) ::_exit(1);
    }
  }
  ::close(pipe_fds[1]);
  int completed = 0;
  char done = 0;
  while (completed < kEventsBeforeKill && ::read(pipe_fds[0], &done, 1) == 1) ++completed;
  ASSERT_EQ(::kill(child, SIGKILL), 0);
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status));
  // Events completed after our count but before the kill are also on disk: read what arrived.
  while (::read(pipe_fds[0], &done, 1) == 1) ++completed;
  ::close(pipe_fds[0]);

  // The recording was never renamed: a killed file is not mistaken for a complete one.
  EXPECT_FALSE(test::RunShell("test -e '" + path + "'").exit_code == 0);
  std::int64_t truncated_at = 0;
  const auto events = ReadAllEvents(path + ".partial", &truncated_at);
  ASSERT_GE(static_cast<int>(events.size()), completed);
  for (int k = 0; k < completed; ++k) {
    EXPECT_EQ(events[static_cast<std::size_t>(k)].data, Payload(k)) << "event " << k;
  }
  LogReader reader(path + ".partial");  // readable as a source too
  EXPECT_FALSE(reader.Next());          // (it holds no frame parts)
}

TEST(RecordingTest, ReadsLogsWrittenByBareLcmLogFile) {
  test::ScratchDir dir;
  {
    lcm::LogFile log(dir / "lcm.lcmlog", "w");
    ASSERT_TRUE(log.good());
    for (int k = 0; k < 4; ++k) {
      std::string text = "event " + std::to_string(k);
      lcm::LogEvent event;
      event.eventnum = k;
      event.timestamp = 1000 * k;
      event.channel = "CHANNEL_" + std::to_string(k % 2);
      event.datalen = static_cast<std::int32_t>(text.size());
      event.data = text.data();
      ASSERT_EQ(log.writeEvent(&event), 0);
    }
  }
  std::int64_t truncated_at = 0;
  const auto events = ReadAllEvents(dir / "lcm.lcmlog", &truncated_at);
  ASSERT_EQ(events.size(), 4u);
  EXPECT_EQ(truncated_at, -1);
  EXPECT_EQ(events[3].channel, "CHANNEL_1");
  EXPECT_EQ(events[3].timestamp_us, 3000);
  EXPECT_EQ(std::string(events[2].data.begin(), events[2].data.end()), "event 2");
}

TEST(RecordingTest, GnssMessagesRoundTripAndImpossibleFixesAreRefused) {
  GnssFix fix;
  fix.stamp_ns = 1'700'000'000'123'456'789;
  fix.latitude_deg = 48.0833;
  fix.longitude_deg = 11.2791;
  fix.altitude_m = 600.5;
  fix.horizontal_sigma_m = 0.02;
  fix.valid = true;
  const auto bytes = EncodeGnssMessage(fix);
  const GnssFix back = DecodeGnssMessage(bytes.data(), bytes.size(), "bus");
  EXPECT_EQ(back.stamp_ns, fix.stamp_ns);
  EXPECT_EQ(back.latitude_deg, fix.latitude_deg);
  EXPECT_EQ(back.longitude_deg, fix.longitude_deg);
  EXPECT_EQ(back.altitude_m, fix.altitude_m);
  EXPECT_TRUE(back.valid);
  const std::string cut = test::ErrorOf([&] { DecodeGnssMessage(bytes.data(), bytes.size() - 3, "bus"); });
  EXPECT_EQ(cut.rfind("bus", 0), 0u) << cut;
  fix.latitude_deg = 200.0;
  const auto impossible = EncodeGnssMessage(fix);
  EXPECT_NE(test::ErrorOf([&] { DecodeGnssMessage(impossible.data(), impossible.size(), "bus"); })
                .find("bus: gnss_fix_t is not a position: latitude 200 deg"),
            std::string::npos);
  // An invalid fix (no reception) carries whatever the receiver left there: not an error.
  fix.valid = false;
  const auto no_fix = EncodeGnssMessage(fix);
  EXPECT_FALSE(DecodeGnssMessage(no_fix.data(), no_fix.size(), "bus").valid);
}

TEST(RecordingTest, UnknownSchemeListsTheKnownOnes) {
  try {
    OpenSource("tape://run.lcmlog");
    FAIL() << "unknown scheme accepted";
  } catch (const romo::Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("unknown source URI scheme 'tape'"), std::string::npos) << message;
    EXPECT_NE(message.find("log://"), std::string::npos) << message;
  }
  EXPECT_THROW(OpenSource("log:///no/such/file.lcmlog"), romo::Error);
}

TEST(RecordingTest, TypeNamesComeFromFingerprints) {
  test::ScratchDir dir;
  {
    LogWriter writer(dir / "run.lcmlog");
    writer.WriteCalibration(Calibration::Load(SampleCalibrationPath()), kStartNs);
    writer.WriteRaw("OTHER", kStartNs, "12345678abc", 11);
  }
  const auto events = ReadAllEvents(dir / "run.lcmlog", nullptr);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(LcmTypeName(events[0].data.data(), events[0].data.size()), "romo_lcm.calibration_t");
  EXPECT_EQ(LcmTypeName(events[1].data.data(), events[1].data.size()), "unknown");
  RegisterLcmType(0x3132333435363738, "test.digits_t");  // "12345678" read big-endian
  EXPECT_EQ(LcmTypeName(events[1].data.data(), events[1].data.size()), "test.digits_t");
}

}  // namespace
}  // namespace romo::drivers
