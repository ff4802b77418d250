// `ultratrack receive`: the scalar receiver end to end on a recording (receiver/receiver_engine.hpp fed by
// receiver/sample_source.hpp), writing solution.csv, NMEA, KML, RINEX 3.04 obs + nav, tracking.csv and
// summary.json into --out (receiver/receiver_outputs.hpp). Options: command-line flags over --config (TOML,
// tools/receive_config.hpp) over the defaults. A progress bar on a terminal, plain lines otherwise.
// Exit: 0 with a fix; 2 (InputError) for bad input, including a file in which no satellite is found (no
// outputs then); 3 when satellites were tracked but the file ended before a fix (outputs written, summary
// says "fix": false). SIGINT stops the loop and still finishes every output.
// --coupling vector: one vector filter closes the channels' code loops (tools/receive_vector.hpp).
// --imu F --coupling loose|tight: GNSS/INS integration on the way (tools/receive_fusion.hpp): nav.csv and a "fusion"
// object in summary.json; exit 3 also when the integration never started, 0 with a fused solution but no PVT fix.
// --imu F --coupling ultra-tight: tight pull-in, then the ultra-tight loop drives the channels
// (tools/receive_ultratight.hpp): ultratight.csv and an "ultratight" object in summary.json.
#include <fmt/core.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cli_parse.hpp"
#include "command_exit.hpp"
#include "commands.hpp"
#include "format_options.hpp"
#include "receive_config.hpp"
#include "receive_fusion.hpp"
#include "receive_ultratight.hpp"
#include "receive_vector.hpp"
#include "receiver/receiver_engine.hpp"
#include "receiver/receiver_outputs.hpp"
#include "receiver/sample_prefetcher.hpp"
#include "receiver/sample_source.hpp"
#include "signals/gps_time.hpp"
#include "signals/input_error.hpp"
#include "signals/rinex_nav.hpp"
#include "signals/sample_format.hpp"

namespace ultratrack::tools {

namespace {

volatile std::sig_atomic_t g_interrupted = 0;
void stop_receiving(int) { g_interrupted = 1; }  // C++ linkage: no clash with other commands' handlers

// Restores the previous SIGINT handler when the command leaves, however it leaves.
struct SigintGuard {
  SigintGuard() : previous(std::signal(SIGINT, stop_receiving)) { g_interrupted = 0; }
  ~SigintGuard() { std::signal(SIGINT, previous); }
  void (*previous)(int);
};

struct ReceiveArgs {
  std::string input, fs, if_hz = "0", config, nav, out;
  std::string elevation_mask, troposphere, ionosphere, channels, prns, duration, skip, reference_week, threads;
  std::string vector_carrier;  // --vector-carrier aided-pll|fll|pll (with --coupling vector)
  FormatArgs format;
  ReceiveFusionArgs fusion;
  bool iq_swap = false, q_negate = false, quiet = false;
};

// The GPS week of the build date: a reference within +-512 weeks of any recording made near it.
int build_week() {
  static const char* months = "JanFebMarAprMayJunJulAugSepOctNovDec";
  const std::string date = __DATE__;  // "Mmm dd yyyy"
  signals::CalendarTime c;
  c.month = static_cast<int>(std::string(months).find(date.substr(0, 3)) / 3) + 1;
  c.day = std::stoi(date.substr(4, 2));
  c.year = std::stoi(date.substr(7, 4));
  return signals::gps_time_from_calendar(c).week;
}

bool on_off(const std::string& option, const std::string& value, const char* on, const char* off) {
  if (value == on) return true;
  if (value == off) return false;
  throw signals::InputError("command line", option + ": '" + value + "' is neither " + on + " nor " + off);
}

class Progress {
 public:
  Progress(bool quiet, double total_s) : quiet_(quiet), tty_(isatty(fileno(stderr)) != 0), total_s_(total_s) {}
  void update(const receiver::ReceiverEngine& engine, bool final = false) {
    if (quiet_) return;
    const double t = receiver::processed_seconds(engine);
    const auto now = std::chrono::steady_clock::now();
    if (!final) {
      if (tty_ && now - last_ < std::chrono::milliseconds(250)) return;
      if (!tty_ && t < next_line_s_) return;
    }
    last_ = now;
    next_line_s_ = t + 10.0;
    const auto& fix = engine.last_fix();
    const std::string status = fix ? fmt::format("fix {:.6f} {:.6f} {:.1f} m ({} sats)", fix->lat_rad * 57.29577951308232,
                                                 fix->lon_rad * 57.29577951308232, fix->height_m, fix->used_prns.size())
                                   : "no fix";
    const int tracked = engine.channels_in_use(), synced = engine.channels_synchronised();
    if (tty_) {
      const double fraction = total_s_ > 0.0 ? std::min(1.0, t / total_s_) : 0.0;
      const int width = 30, filled = static_cast<int>(fraction * width);
      fmt::print(stderr, "\r[{}{}] {:6.1f}/{:.1f} s  tracking {:2d} (synced {:2d})  {}   ", std::string(filled, '#'),
                 std::string(width - filled, '.'), t, total_s_, tracked, synced, status);
      if (final) fmt::print(stderr, "\n");
    } else {
      fmt::print(stderr, "receive: {:.1f}/{:.1f} s, tracking {} (synced {}), {}\n", t, total_s_, tracked, synced,
                 status);
    }
  }

 private:
  bool quiet_, tty_;
  double total_s_;
  double next_line_s_ = 0.0;
  std::chrono::steady_clock::time_point last_{};
};

void run_receive(const ReceiveArgs& args) {
  const auto format = parse_format(args.format);
  receiver::SampleSourceOptions source_options;
  source_options.two_bit = parse_two_bit_layout(args.format);
  source_options.fs_hz = parse_double_option("--fs", args.fs);
  source_options.if_hz = parse_double_option("--if", args.if_hz);
  source_options.iq_swap = args.iq_swap;
  source_options.q_negate = args.q_negate;
  const double skip_s = args.skip.empty() ? 0.0 : parse_double_option("--skip", args.skip);
  if (skip_s < 0.0) throw signals::InputError("command line", "--skip: must not be negative");
  source_options.start_sample = std::llround(skip_s * source_options.fs_hz);

  receiver::ReceiverOptions options;
  options.fs_hz = source_options.fs_hz;
  if (!args.config.empty()) apply_receive_config(args.config, options);
  if (!args.elevation_mask.empty())
    options.pvt.elevation_mask_rad = parse_double_option("--elevation-mask-deg", args.elevation_mask) * M_PI / 180.0;
  if (!args.troposphere.empty()) options.pvt.troposphere = on_off("--troposphere", args.troposphere, "on", "off");
  if (!args.ionosphere.empty()) options.pvt.ionosphere = on_off("--ionosphere", args.ionosphere, "broadcast", "off");
  if (!args.channels.empty()) options.channels = parse_int_option("--channels", args.channels);
  if (!args.threads.empty()) options.threads = parse_int_option("--threads", args.threads);
  if (!args.prns.empty()) options.prns = parse_prn_list_option("--prn", args.prns);
  signals::RinexNavData nav;
  if (!args.nav.empty()) nav = signals::read_rinex_nav(args.nav);
  if (!args.reference_week.empty()) {
    options.reference_week = parse_int_option("--reference-week", args.reference_week);
    options.reference_week_is_signal_week = true;
  } else if (options.reference_week == 0) {
    // A nav file dates the recording; the build date only bounds it (+-512 weeks for the 10-bit WN).
    options.reference_week = nav.ephemerides.empty() ? build_week() : nav.ephemerides.front().week;
    options.reference_week_is_signal_week = !nav.ephemerides.empty();
  }
  const double duration_s = args.duration.empty() ? 0.0 : parse_double_option("--duration", args.duration);
  if (duration_s < 0.0) throw signals::InputError("command line", "--duration: must not be negative");
  if (args.out.empty()) throw signals::InputError("command line", "--out: an output folder is required");
  if (const std::string why = options.validate(); !why.empty()) throw signals::InputError(args.config.empty() ? "command line" : args.config, why);

  receiver::SampleSource source(args.input, format, source_options);
  const std::int64_t available = source.total_samples() - source_options.start_sample;
  std::int64_t to_process = available;
  if (duration_s > 0.0) to_process = std::min<std::int64_t>(to_process, std::llround(duration_s * options.fs_hz));
  const receiver::AcquisitionOptions acq = [&] {
    auto a = options.acquisition;
    a.fs_hz = options.fs_hz;
    return a;
  }();
  const auto needed = static_cast<std::int64_t>(acq.noncoherent * std::llround(acq.coherent_s() * options.fs_hz));
  if (to_process < needed)
    throw signals::InputError(args.input, fmt::format("holds {} samples to process, fewer than the {} that one "
                                                      "acquisition needs ({} x {} ms)",
                                                      to_process, needed, acq.noncoherent, acq.coherent_ms));

  // GNSS/INS integration (--coupling): settings and the IMU file checked before any output exists.
  const auto fusion_settings = parse_receive_fusion(args.fusion);
  std::vector<ins::ImuIncrement> imu;
  if (fusion_settings) imu = read_receive_imu(*fusion_settings);

  receiver::ReceiverOutputs outputs(args.out, options.fs_hz, options.observation_interval_s);
  std::optional<ReceiveFusion> fusion;
  if (fusion_settings) fusion.emplace(*fusion_settings, std::move(imu), outputs, args.out, options, nav.ephemerides);
  receiver::ReceiverEngine engine(options, fusion ? static_cast<receiver::ReceiverObserver&>(*fusion) : outputs);
  if (fusion) fusion->attach(engine);
  if (!nav.ephemerides.empty()) engine.add_navigation(nav.ephemerides, nav.klobuchar, nav.utc);
  const ReceiveCoupling coupling = parse_receive_coupling(args.fusion.coupling);
  if (!args.vector_carrier.empty() && coupling != ReceiveCoupling::Vector)
    throw signals::InputError("command line", "--vector-carrier needs --coupling vector");
  const fusion::VectorCarrier vector_carrier =
      args.vector_carrier.empty() ? fusion::VectorCarrier::kAidedPll : parse_vector_carrier(args.vector_carrier);
  std::unique_ptr<ReceiveVector> vector;  // --coupling vector: the vector tracking filter closes the code loops
  if (coupling == ReceiveCoupling::Vector)
    (vector = std::make_unique<ReceiveVector>(options, args.out, vector_carrier))->attach(engine);
  std::unique_ptr<ReceiveUltraTight> ultratight;  // --coupling ultra-tight: the INS-predicted replica drives them
  if (coupling == ReceiveCoupling::UltraTight)
    (ultratight = std::make_unique<ReceiveUltraTight>(*fusion, options, args.out))->attach(engine);

  SigintGuard sigint;
  Progress progress(args.quiet, static_cast<double>(to_process) / options.fs_hz);
  const auto block_size = static_cast<std::size_t>(std::max<std::int64_t>(1, std::llround(0.05 * options.fs_hz)));
  const auto wall_start = std::chrono::steady_clock::now();
  // With more than one thread the next block is read (and converted to int16) while this one is processed.
  receiver::SamplePrefetcher reader(source, block_size, to_process, engine.threads() > 1);
  while (!g_interrupted) {
    const receiver::PrefetchedBlock got = reader.next();
    if (got.where.count == 0) break;
    engine.process(got.samples, got.where.first_sample, {got.re, got.im}, got.i16_gain);
    reader.set_i16_gain(engine.i16_gain());
    progress.update(engine);
  }
  engine.finish_vector_loop();  // a pipelined loop's last update
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  progress.update(engine, true);

  const auto& stats = engine.stats();
  bool acquired = false;
  for (int prn = 1; prn <= 32; ++prn) acquired = acquired || stats.satellites[static_cast<std::size_t>(prn)].acquisitions > 0;
  if (!acquired && !g_interrupted)
    throw signals::InputError(args.input, fmt::format("no GPS L1 C/A satellite found in {:.1f} s of signal: check "
                                                      "--format, --fs, --if, --iq-swap/--q-negate",
                                                      receiver::processed_seconds(engine)));

  receiver::RunDescription run;
  run.input = args.input;
  run.format = args.format.format;
  if (signals::is_two_bit(format))
    run.format += fmt::format(" ({}, {})", signals::to_string(source_options.two_bit.coding),
                              signals::to_string(source_options.two_bit.order));
  run.fs_hz = options.fs_hz;
  run.if_hz = source_options.if_hz;
  run.skip_s = skip_s;
  run.wall_time_s = wall_s;
  run.interrupted = g_interrupted != 0;
  run.coupling = to_string(coupling);
  if (fusion) {
    fusion->finish(engine.stats().first_sample + engine.stats().samples_processed);
    run.extra_json = fusion->summary_json();
  }
  if (ultratight) {
    ultratight->finish(engine.stats().first_sample + engine.stats().samples_processed);
    run.extra_json += ",\n  " + ultratight->summary_json();
  }
  if (vector) {
    vector->finish();
    run.extra_json = vector->summary_json();
  }
  outputs.finish(engine, run);
  if (fusion) fusion->commit();
  if (vector)
    fmt::print("receive: vector tracking: {} epochs with channels in vector mode ({} channel-epochs), filter started "
               "{} times, reset {} times; {} channel-epochs coasting\n", vector->vector_epochs(), vector->vector_channel_epochs(),
               vector->filter().initialisations(), vector->filter().resets(), vector->coasting_channel_epochs());

  const double t = receiver::processed_seconds(engine);
  fmt::print("receive: {:.1f} s of signal in {:.2f} s ({:.1f}x real time, {} threads){}\n", t, wall_s,
             wall_s > 0 ? t / wall_s : 0.0, engine.threads(), run.interrupted ? ", interrupted" : "");
  int used = 0, tracked = 0;
  for (int prn = 1; prn <= 32; ++prn) {
    used += stats.satellites[static_cast<std::size_t>(prn)].used_in_fixes > 0;
    tracked += engine.tracked_time_s(prn) > 0.0;
  }
  fmt::print("receive: satellites tracked {}, used {}; fixes {}; ephemerides decoded {}\n", tracked, used, stats.fixes,
             engine.decoded_ephemerides().size());
  if (fusion) fmt::print("{}\n", fusion->report());
  if (ultratight) fmt::print("{}\n", ultratight->report());
  if (fusion && !fusion->started())
    throw CommandExit(3, fmt::format("{}: no fused solution ({}); outputs up to the end are in {}", args.input,
                                     fusion->not_started_reason(), args.out));
  if (stats.fixes == 0 && !(fusion && fusion->started()))
    throw CommandExit(3, fmt::format("{}: no position fix in {:.1f} s of signal ({} satellites tracked, {} "
                                     "ephemerides decoded; --nav gives a hot start); outputs up to the end are in {}",
                                     args.input, t, tracked, engine.decoded_ephemerides().size(), args.out));
  if (stats.fixes == 0) return;  // a fused solution without any PVT fix (tight coupling)
  const auto& s = stats;
  fmt::print("receive: first fix after {:.2f} s; mean position {:.7f} deg, {:.7f} deg, {:.2f} m; outputs in {}\n",
             receiver::ttff_seconds(engine), s.sum_lat_rad / s.fixes * 180.0 / M_PI,
             s.sum_lon_rad / s.fixes * 180.0 / M_PI, s.sum_height_m / s.fixes, args.out);
}

}  // namespace

void add_receive_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("receive", "Receive a recording: acquisition, tracking, decoding, observables, PVT");
  auto args = std::make_shared<ReceiveArgs>();
  cmd->add_option("--input", args->input, "IF sample file")->required();
  add_format_options(cmd, args->format);
  cmd->add_option("--fs", args->fs, "sample rate, Hz")->required();
  cmd->add_option("--if", args->if_hz, "intermediate frequency, Hz (0: complex baseband)")->capture_default_str();
  cmd->add_option("--out", args->out, "output folder (created when missing)")->required();
  cmd->add_option("--config", args->config, "TOML file with [receiver], [acquisition], [tracking], [pvt] settings");
  cmd->add_option("--nav", args->nav, "RINEX navigation file: ephemerides known from the start (hot start)");
  cmd->add_option("--elevation-mask-deg", args->elevation_mask, "PVT elevation mask, degrees (default 10)");
  cmd->add_option("--troposphere", args->troposphere, "on|off (default on)");
  cmd->add_option("--ionosphere", args->ionosphere, "broadcast|off (default broadcast: a default Klobuchar set until the nav file's or the broadcast one is known)");
  cmd->add_option("--channels", args->channels, "tracking channels (default 12)");
  cmd->add_option("--threads", args->threads, "worker threads including the main one (default: all cores)");
  cmd->add_option("--prn", args->prns, "PRNs to search, e.g. 1-32 or 3,7,12-15 (default all)");
  cmd->add_option("--duration", args->duration, "seconds of signal to process (default: to the end)");
  cmd->add_option("--skip", args->skip, "seconds of signal to skip at the start");
  cmd->add_option("--reference-week", args->reference_week,
                  "full GPS week near the recording, for the 10-bit week (default: nav file or build date)");
  cmd->add_option("--vector-carrier", args->vector_carrier,
                  "with --coupling vector: aided-pll (default: each channel's PLL, aided), fll (the filter "
                  "commands the carrier NCOs: vector FLL) or pll (the filter commands the carrier NCOs' frequency "
                  "and phase from per-channel carrier states its Costas discriminators update: vector PLL)");
  cmd->add_flag("--iq-swap", args->iq_swap, "exchange I and Q (complex formats)");
  cmd->add_flag("--q-negate", args->q_negate, "negate Q (complex) / invert the spectrum (real IF)");
  add_receive_fusion_options(cmd, args->fusion);
  cmd->add_flag("--quiet", args->quiet, "no progress display");
  cmd->callback([args] { run_receive(*args); });
}

}  // namespace ultratrack::tools
