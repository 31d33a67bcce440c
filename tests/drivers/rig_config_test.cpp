#include <string>

#include <gtest/gtest.h>

#include "romo/core/check.hpp"
#include "romo/drivers/gige.hpp"
#include "test_support.hpp"

namespace romo::drivers {
namespace {

constexpr const char* kGoodYaml = R"(
discovery_timeout_s: 3
packet_socket: true
rigs:
  - rig_id: 0
    name: front
    left: {serial: "AVT-1001"}
    right: {serial: "AVT-1002"}
    pixel_format: BayerRG8
    exposure_us: 8000
    gain_db: 2.5
    frame_rate_hz: 10
    packet_size: 1500
    trigger: software
    pairing_tolerance_ms: 2
    calibration: calib.yaml
  - rig_id: 3
    left: {address: 10.0.0.7}
    right: {address: 10.0.0.8}
    pixel_format: Mono12
)";

// Expects FromYaml(@p yaml) to throw a romo::Error whose message names every piece of @p parts.
void ExpectError(const std::string& yaml, std::initializer_list<const char*> parts) {
  try {
    GigeConfig::FromYaml(yaml, "rigs.yaml");
    FAIL() << "expected an error for:\n" << yaml;
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("rigs.yaml"), std::string::npos) << message;
    for (const char* part : parts) {
      EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
    }
  }
}

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

TEST(RigConfigTest, ReadsEveryFieldAndResolvesCalibrationBesideTheFile) {
  const GigeConfig config = GigeConfig::FromYaml(kGoodYaml, "rigs.yaml", "/etc/romo");
  ASSERT_EQ(config.rigs.size(), 2u);
  EXPECT_DOUBLE_EQ(config.discovery_timeout_s, 3.0);
  EXPECT_TRUE(config.packet_socket);
  const GigeRigConfig& front = config.rigs[0];
  EXPECT_EQ(front.rig_id, 0);
  EXPECT_EQ(front.name, "front");
  EXPECT_EQ(front.left.serial, "AVT-1001");
  EXPECT_EQ(front.right.Describe(), "serial:AVT-1002");
  EXPECT_EQ(front.pixel_format, GigePixelFormat::kBayerRG8);
  EXPECT_EQ(DeliveredFormat(front.pixel_format), PixelFormat::kRgb8);
  EXPECT_DOUBLE_EQ(front.exposure_us, 8000.0);
  EXPECT_DOUBLE_EQ(front.gain_db, 2.5);
  EXPECT_EQ(front.packet_size_bytes, 1500);
  EXPECT_EQ(front.trigger, TriggerMode::kSoftware);
  EXPECT_DOUBLE_EQ(front.pairing_tolerance_ms, 2.0);
  EXPECT_EQ(front.calibration_path, "/etc/romo/calib.yaml");
  const GigeRigConfig& side = config.rigs[1];
  EXPECT_EQ(side.left.Describe(), "ip:10.0.0.7");
  EXPECT_EQ(DeliveredFormat(side.pixel_format), PixelFormat::kMono16);
  EXPECT_EQ(side.trigger, TriggerMode::kFreeRun);
}

TEST(RigConfigTest, YamlRoundTripKeepsEveryValue) {
  const GigeConfig config = GigeConfig::FromYaml(kGoodYaml, "rigs.yaml", "/etc/romo");
  const GigeConfig again = GigeConfig::FromYaml(config.ToYaml(), "round-trip");
  EXPECT_EQ(again.ToYaml(), config.ToYaml());
  EXPECT_EQ(again.rigs[1].left.address, "10.0.0.7");
}

TEST(RigConfigTest, ShippedExamplesLoad) {
  const GigeConfig one = GigeConfig::Load(test::SourcePath("config/rigs/single_rig.yaml"));
  EXPECT_EQ(one.rigs.size(), 1u);
  EXPECT_FALSE(one.packet_socket) << "UDP sockets unless asked: they never mix cameras";
  const GigeConfig romo = GigeConfig::Load(test::SourcePath("config/rigs/romo_6rigs.yaml"));
  ASSERT_EQ(romo.rigs.size(), 6u);
  EXPECT_EQ(DeliveredFormat(romo.rigs[0].pixel_format), PixelFormat::kRgb8);  // colour front rig
  for (std::size_t i = 1; i < romo.rigs.size(); ++i) {
    EXPECT_EQ(romo.rigs[i].pixel_format, GigePixelFormat::kMono12) << i;
  }
}

TEST(RigConfigTest, MissingAndGarbledFilesNameTheFile) {
  test::ScratchDir dir;
  try {
    GigeConfig::Load(dir / "nope.yaml");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("nope.yaml"), std::string::npos) << e.what();
  }
  test::WriteFile(dir / "garbled.yaml", "rigs: [ {rig_id: 0, left: {serial: a\n  : : ]]");
  try {
    GigeConfig::Load(dir / "garbled.yaml");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("garbled.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("line"), std::string::npos) << e.what();
  }
  ExpectError("", {"rigs"});
  ExpectError("- just a list", {"rigs"});
  ExpectError("rigs: 7", {"rigs", "7"});
  ExpectError("rigs: []", {"rigs", "at least one"});
}

TEST(RigConfigTest, EachBadValueNamesFieldAndValue) {
  const std::string good = kGoodYaml;
  ExpectError(Replace(good, "rig_id: 3", "rig_id: 0"), {"rigs[1].rig_id", "0"});
  ExpectError(Replace(good, "rig_id: 3", "rig_id: three"), {"rigs[1].rig_id", "three"});
  ExpectError(Replace(good, "rig_id: 3", "name: side"), {"rigs[1].rig_id", "missing"});
  ExpectError(Replace(good, "BayerRG8", "Mono10"), {"rigs[0].pixel_format", "Mono10", "Mono12"});
  ExpectError(Replace(good, "exposure_us: 8000", "exposure_us: -5"), {"rigs[0].exposure_us", "-5"});
  ExpectError(Replace(good, "exposure_us: 8000", "exposure_us: fast"), {"rigs[0].exposure_us", "fast"});
  ExpectError(Replace(good, "gain_db: 2.5", "gain_db: 99"), {"rigs[0].gain_db", "99"});
  ExpectError(Replace(good, "frame_rate_hz: 10", "frame_rate_hz: 0"), {"rigs[0].frame_rate_hz", "0"});
  ExpectError(Replace(good, "packet_size: 1500", "packet_size: 100"), {"rigs[0].packet_size", "100"});
  ExpectError(Replace(good, "trigger: software", "trigger: hardware"), {"rigs[0].trigger", "hardware"});
  ExpectError(Replace(good, "pairing_tolerance_ms: 2", "pairing_tolerance_ms: 60"),
              {"rigs[0].pairing_tolerance_ms", "60", "half the frame period"});
  ExpectError(Replace(good, "10.0.0.7", "10.0.0.300"), {"rigs[1].left.address", "10.0.0.300"});
  ExpectError(Replace(good, "10.0.0.8", "10.0.0.7"), {"rigs[1].right", "ip:10.0.0.7", "already used"});
  ExpectError(Replace(good, "left: {address: 10.0.0.7}", "left: {address: 10.0.0.7, serial: X}"),
              {"rigs[1].left", "exactly one"});
  ExpectError(Replace(good, "    left: {address: 10.0.0.7}\n", ""), {"rigs[1].left", "missing"});
  ExpectError(Replace(good, "exposure_us: 8000", "exposure: 8000"), {"rigs[0].exposure", "unknown field"});
  // A complex key (found by fuzz_rig_yaml: it escaped as yaml-cpp's BadConversion).
  ExpectError(Replace(good, "exposure_us: 8000", "? [a, b]\n    : 8000"), {"rigs[0].(key)", "plain text"});
  ExpectError(Replace(good, "discovery_timeout_s: 3", "discovery_timeout_s: 0"), {"discovery_timeout_s", "0"});
  ExpectError(Replace(good, "packet_socket: true", "packet_socket: maybe"), {"packet_socket", "maybe", "true or false"});
}

TEST(RigConfigTest, UnknownGigeQueryKeyIsAnError) {
  test::ScratchDir dir;
  test::WriteFile(dir / "rigs.yaml", kGoodYaml);
  try {
    OpenSource("gige://" + dir / "rigs.yaml" + "?stall=3");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("stall"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace romo::drivers
