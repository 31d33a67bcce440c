// `romo bench gige`: N emulated GigE cameras (a child process) grabbed through gige:// for a fixed
// time: frames dropped per camera and CPU per camera, against Aravis's own arv-camera-test-0.8
// grabbing the same cameras in the same run (the baseline).
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/command_registry.hpp"
#include "cli/progress.hpp"
#include "romo/core/check.hpp"
#include "romo/drivers/gige.hpp"

namespace romo::tools {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct Options {
  double seconds = 10.0;
  int rigs = 6;
  double rate_hz = 10.0;
  int width = 782;
  int height = 582;
  bool baseline = true;
  bool packet_socket = false;  // both romo and the baseline receive the same way
  std::string netns_run;
};

std::string Link(const char* path) {
  std::error_code error;
  return fs::read_symlink(path, error).string();
}

// GigE discovery broadcasts on every interface, so the benchmark only runs in a private network
// namespace (a different one from init's).
bool InPrivateNetworkNamespace() {
  const std::string own = Link("/proc/self/ns/net");
  const std::string init = Link("/proc/1/ns/net");
  return !own.empty() && !init.empty() && own != init;
}

// CPU seconds (user + system) of process @p pid from /proc.
double ProcessCpuSeconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto close = text.rfind(')');
  if (close == std::string::npos) return 0.0;
  std::istringstream fields(text.substr(close + 2));
  std::string field;
  unsigned long long utime = 0, stime = 0;
  for (int i = 3; i <= 15 && fields >> field; ++i) {
    if (i == 14) utime = std::stoull(field);
    if (i == 15) stime = std::stoull(field);
  }
  return static_cast<double>(utime + stime) / static_cast<double>(sysconf(_SC_CLK_TCK));
}

double SelfCpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec + 1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

std::string Address(int camera) { return "127.0.0." + std::to_string(2 + camera); }

std::vector<drivers::GigeEmulator::Camera> MakeCameras(const Options& options) {
  std::vector<drivers::GigeEmulator::Camera> cameras;
  for (int rig = 0; rig < options.rigs; ++rig) {
    for (int side = 0; side < 2; ++side) {
      drivers::GigeEmulator::Camera camera;
      camera.address = Address(2 * rig + side);
      camera.serial = "bench-" + std::to_string(2 * rig + side);
      // RoMo: a colour front rig, 12-bit mono elsewhere.
      const auto format = rig == 0 ? drivers::PixelFormat::kRgb8 : drivers::PixelFormat::kMono16;
      for (int k = 0; k < 4; ++k) {
        drivers::Image image = drivers::Image::Allocate(format, options.width, options.height);
        for (std::size_t i = 0; i < image.data.size(); ++i) {
          image.data[i] = static_cast<std::uint8_t>((i * 31 + k * 17 + rig * 5) >> 3);
        }
        if (format == drivers::PixelFormat::kMono16) {
          for (std::size_t i = 1; i < image.data.size(); i += 2) image.data[i] &= 0x0f;  // 12-bit
        }
        camera.frames.push_back(std::move(image));
      }
      cameras.push_back(std::move(camera));
    }
  }
  return cameras;
}

// Forks the emulator process; returns its pid once its cameras answer.
pid_t StartEmulator(const Options& options) {
  int ready[2];
  if (pipe(ready) != 0) Fail("bench gige: pipe failed");
  const pid_t pid = fork();
  if (pid == 0) {
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    close(ready[0]);
    try {
      drivers::GigeEmulator emulator(MakeCameras(options), options.rate_hz, /*loop=*/true);
      const char byte = 1;
      if (write(ready[1], &byte, 1) != 1) _exit(1);
      while (true) pause();  // until the parent kills it
    } catch (const std::exception& e) {
      std::fprintf(stderr, "bench gige: emulator: %s\n", e.what());
      _exit(1);
    }
  }
  close(ready[1]);
  pollfd fd{ready[0], POLLIN, 0};
  char byte = 0;
  const bool ok = poll(&fd, 1, 30000) == 1 && read(ready[0], &byte, 1) == 1;
  close(ready[0]);
  if (!ok) {
    kill(pid, SIGKILL);
    waitpid(pid, nullptr, 0);
    Fail("bench gige: the emulated cameras did not start");
  }
  return pid;
}

void Wait(double seconds, Progress* progress, double* done_s) {
  const auto end = Clock::now() + std::chrono::duration<double>(seconds);
  while (Clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    *done_s += 0.1;
    progress->Update(static_cast<std::uint64_t>(*done_s * 10));
  }
}

void Run(const Options& options, const std::string& self_args) {
  // ROMO_NETNS_REEXEC marks the re-run, where /proc/1 may not be readable to compare against.
  if (!InPrivateNetworkNamespace() && !std::getenv("ROMO_NETNS_REEXEC")) {
    std::string runner = options.netns_run;
    if (runner.empty() && std::getenv("ROMO_NETNS_RUN")) runner = std::getenv("ROMO_NETNS_RUN");
    if (runner.empty() && fs::exists("../shared/scripts/netns-run")) runner = fs::absolute("../shared/scripts/netns-run");
    if (runner.empty()) {
      Fail("romo bench gige needs a private network namespace (GigE discovery broadcasts on every "
           "interface): run it as `netns-run romo bench gige ...`, or give --netns-run PATH");
    }
    // Re-run this same command inside the namespace.
    const std::string self = Link("/proc/self/exe");
    const std::string command = "ROMO_NETNS_REEXEC=1 '" + runner + "' '" + self + "' " + self_args;
    std::fflush(stdout);
    const int status = std::system(command.c_str());
    if (status != 0) throw CLI::RuntimeError(WIFEXITED(status) ? WEXITSTATUS(status) : kExitRuntimeFailure);
    return;
  }
  const int cameras = 2 * options.rigs;
  const double warmup_s = 1.5;
  std::printf("romo bench gige: %d emulated cameras (%d rigs), %dx%d (rig 0 RGB8, others Mono16), "
              "%.1f Hz, %.1f s per run, received through %s\n",
              cameras, options.rigs, options.width, options.height, options.rate_hz, options.seconds,
              options.packet_socket ? "Aravis' packet socket" : "UDP sockets");
  std::fflush(stdout);
  const pid_t emulator = StartEmulator(options);
  Progress progress("bench gige", static_cast<std::uint64_t>(
                                      10 * (options.baseline ? 2 : 1) * (options.seconds + warmup_s)));
  double done_s = 0.0;

  drivers::GigeConfig config;
  config.stall_timeout_s = 10.0;
  config.packet_socket = options.packet_socket;
  for (int rig = 0; rig < options.rigs; ++rig) {
    drivers::GigeRigConfig rig_config;
    rig_config.rig_id = rig;
    rig_config.left.address = Address(2 * rig);
    rig_config.right.address = Address(2 * rig + 1);
    rig_config.pixel_format = rig == 0 ? drivers::GigePixelFormat::kRgb8 : drivers::GigePixelFormat::kMono16;
    rig_config.frame_rate_hz = options.rate_hz;
    rig_config.pairing_tolerance_ms = std::min(5.0, 250.0 / options.rate_hz);
    config.rigs.push_back(rig_config);
  }

  // Run 1: romo's gige:// source, frame sets consumed as fast as they come.
  std::vector<drivers::GigeCameraDiagnostics> before, after;
  double romo_cpu = 0.0, emulator_cpu_romo = 0.0;
  std::uint64_t sets = 0, sets_complete = 0;
  {
    drivers::GigeSource source(config, "bench");
    std::atomic<bool> stop{false};
    std::atomic<std::uint64_t> consumed{0}, complete{0};
    std::thread consumer([&] {
      while (!stop) {
        auto set = source.Next();
        if (!set) break;
        ++consumed;
        if (static_cast<int>(set->stereo.size()) == options.rigs) ++complete;
      }
    });
    Wait(warmup_s, &progress, &done_s);
    before = source.diagnostics();
    const std::uint64_t sets0 = consumed, complete0 = complete;
    const double cpu0 = SelfCpuSeconds(), emu0 = ProcessCpuSeconds(emulator);
    Wait(options.seconds, &progress, &done_s);
    romo_cpu = SelfCpuSeconds() - cpu0;
    emulator_cpu_romo = ProcessCpuSeconds(emulator) - emu0;
    after = source.diagnostics();
    sets = consumed - sets0;
    sets_complete = complete - complete0;
    stop = true;
    consumer.join();
  }

  // Run 2: the baseline, one arv-camera-test-0.8 per camera (bare Aravis acquisition, no pairing).
  double baseline_cpu = 0.0, emulator_cpu_baseline = 0.0;
  if (options.baseline) {
    std::vector<pid_t> grabbers;
    for (int camera = 0; camera < cameras; ++camera) {
      const pid_t pid = fork();
      if (pid == 0) {
        prctl(PR_SET_PDEATHSIG, SIGKILL);
        if (!freopen("/dev/null", "w", stdout) || !freopen("/dev/null", "w", stderr)) _exit(127);
        const std::string rate = std::to_string(options.rate_hz), address = Address(camera);
        std::vector<const char*> argv = {"arv-camera-test-0.8", "-n", address.c_str(), "-f", rate.c_str()};
        // Through a UDP socket it needs a receive buffer of a frame or more, as romo sizes its own.
        if (!options.packet_socket) argv.insert(argv.end(), {"--no-packet-socket", "--auto"});
        argv.push_back(nullptr);
        execvp(argv[0], const_cast<char* const*>(argv.data()));
        _exit(127);
      }
      grabbers.push_back(pid);
    }
    Wait(warmup_s, &progress, &done_s);
    double cpu0 = 0.0;
    for (pid_t pid : grabbers) cpu0 += ProcessCpuSeconds(pid);
    const double emu0 = ProcessCpuSeconds(emulator);
    Wait(options.seconds, &progress, &done_s);
    for (pid_t pid : grabbers) baseline_cpu += ProcessCpuSeconds(pid);
    baseline_cpu -= cpu0;
    emulator_cpu_baseline = ProcessCpuSeconds(emulator) - emu0;
    for (pid_t pid : grabbers) {
      kill(pid, SIGKILL);
      waitpid(pid, nullptr, 0);
    }
  }
  progress.Finish();
  kill(emulator, SIGKILL);
  waitpid(emulator, nullptr, 0);

  const double expected = options.seconds * options.rate_hz;
  std::printf("\n%-16s %9s %9s %10s %8s %8s %10s\n", "camera", "expected", "completed", "incomplete",
              "dropped", "unpaired", "reconnects");
  std::uint64_t total_lost = 0;
  for (std::size_t i = 0; i < after.size(); ++i) {
    const auto& a = after[i].counters;
    const auto& b = before[i].counters;
    const std::uint64_t dropped = a.dropped - b.dropped;
    total_lost += dropped + (a.incomplete - b.incomplete);
    std::printf("%-16s %9.0f %9llu %10llu %8llu %8llu %10llu\n", a.camera_id.c_str(), expected,
                static_cast<unsigned long long>(a.completed - b.completed),
                static_cast<unsigned long long>(a.incomplete - b.incomplete),
                static_cast<unsigned long long>(dropped),
                static_cast<unsigned long long>(a.unpaired - b.unpaired),
                static_cast<unsigned long long>(a.reconnects - b.reconnects));
  }
  const double per_camera = 100.0 / (options.seconds * cameras);  // -> % of one core per camera
  std::printf("\nframe sets delivered: %llu (%llu with all %d rigs), expected %.0f\n",
              static_cast<unsigned long long>(sets), static_cast<unsigned long long>(sets_complete),
              options.rigs, expected);
  std::printf("frames lost (dropped + incomplete), all cameras: %llu of %.0f expected\n",
              static_cast<unsigned long long>(total_lost), expected * cameras);
  std::printf("CPU per camera, %% of one core: romo gige:// %.2f", romo_cpu * per_camera);
  if (options.baseline) {
    std::printf(" | baseline arv-camera-test-0.8 %.2f | ratio romo/baseline %.2f",
                baseline_cpu * per_camera, baseline_cpu > 0 ? romo_cpu / baseline_cpu : 0.0);
  }
  std::printf("\nCPU per camera of the emulator process, %% of one core: %.2f during romo", emulator_cpu_romo * per_camera);
  if (options.baseline) std::printf(", %.2f during baseline", emulator_cpu_baseline * per_camera);
  std::printf("\n");
}

void Register(CLI::App& root) {
  CLI::App& bench = CommandGroup(root, "bench", "Benchmarks (ratios against a named baseline in the same run)");
  auto options = std::make_shared<Options>();
  auto* command = bench.add_subcommand(
      "gige", "Emulated GigE cameras grabbed through gige://: frames dropped and CPU per camera "
              "against arv-camera-test-0.8 (runs itself inside netns-run)");
  command->add_option("--seconds", options->seconds, "Measured seconds per run (default 10)")
      ->check(CLI::Range(1.0, 600.0));
  command->add_option("--rigs", options->rigs, "Stereo rigs, 2 cameras each (default 6 = 12 cameras; at most 8)")
      ->check(CLI::Range(1, 8));
  command->add_option("--rate", options->rate_hz, "Frame rate in Hz (default 10)")->check(CLI::Range(0.5, 100.0));
  command->add_option("--width", options->width, "Image width (default 782)")->check(CLI::Range(16, 4096));
  command->add_option("--height", options->height, "Image height (default 582)")->check(CLI::Range(16, 4096));
  command->add_flag("!--no-baseline", options->baseline, "Skip the arv-camera-test-0.8 baseline run");
  command->add_flag("--packet-socket", options->packet_socket,
                    "Receive through Aravis' AF_PACKET ring (rig config packet_socket: true), romo "
                    "and baseline alike; default: UDP sockets for both");
  command->add_option("--netns-run", options->netns_run,
                      "netns-run script used to re-run inside a private network namespace");
  command->callback([options] {
    std::ostringstream args;
    args << "bench gige --seconds " << options->seconds << " --rigs " << options->rigs << " --rate "
         << options->rate_hz << " --width " << options->width << " --height " << options->height
         << (options->baseline ? "" : " --no-baseline") << (options->packet_socket ? " --packet-socket" : "");
    Run(*options, args.str());
  });
}

ROMO_REGISTER_COMMAND(Register);

}  // namespace
}  // namespace romo::tools
