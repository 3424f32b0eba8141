// `stereorig check` on bad input, through the binary (issue 6): every case
// exits 2 with one line on stderr that names the file, writes no report, and
// leaves the SQLite history exactly as it was (same bytes, integrity "ok",
// same number of runs). The cases: a corrupt image, an image of the wrong
// size, captures from another rig (other cameras, more cameras, another
// camera model), and a history path that is not a database.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <thread>

#include "calib/core/rig_file.h"
#include "targets/target_file.h"
#include "tests/cli_runner.h"
#include "tests/made_once.h"

namespace stereorig {
namespace {

namespace fs = std::filesystem;
using testing::kBin;
using testing::Lines;
using testing::Result;
using testing::RunCli;

std::string Bytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

std::string LastLine(const std::string& text) {
  const size_t end = text.find_last_not_of('\n');
  if (end == std::string::npos) return "";
  const size_t start = text.rfind('\n', end);
  return text.substr(start == std::string::npos ? 0 : start + 1,
                     end - (start == std::string::npos ? 0 : start + 1) + 1);
}

int Occurrences(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// What an independent reader (the SQLite library itself) says about the
// history: its integrity check and the number of runs.
struct DbState {
  std::string integrity;
  int runs = -1;
  std::string last_rig_path, last_rig_crc32, last_board;  // the last run's inputs
  std::string last_rig_file;                              // the last run's rig_file (stereorig_check_runs)
  std::string last_captures;                              // the last run's captures (stereorig_check_runs)
};
DbState ReadDb(const std::string& path) {
  DbState s;
  sqlite3* db = nullptr;
  if (sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    sqlite3_close(db);
    return s;
  }
  auto one = [&](const char* sql) {
    std::string v;
    sqlite3_stmt* st = nullptr;
    if (sqlite3_prepare_v2(db, sql, -1, &st, nullptr) == SQLITE_OK && sqlite3_step(st) == SQLITE_ROW)
      v = reinterpret_cast<const char*>(sqlite3_column_text(st, 0));
    sqlite3_finalize(st);
    return v;
  };
  s.integrity = one("PRAGMA integrity_check");
  const std::string n = one("SELECT COUNT(*) FROM stereorig_check_runs");
  s.runs = n.empty() ? -1 : std::stoi(n);
  s.last_rig_path = one("SELECT rig_path FROM stereorig_check_run_inputs ORDER BY run_id DESC LIMIT 1");
  s.last_rig_crc32 = one("SELECT rig_crc32 FROM stereorig_check_run_inputs ORDER BY run_id DESC LIMIT 1");
  s.last_board = one("SELECT board FROM stereorig_check_run_inputs ORDER BY run_id DESC LIMIT 1");
  s.last_rig_file = one("SELECT rig_file FROM stereorig_check_runs ORDER BY id DESC LIMIT 1");
  s.last_captures = one("SELECT captures FROM stereorig_check_runs ORDER BY id DESC LIMIT 1");
  sqlite3_close(db);
  return s;
}

// The simulator's truth rig as a calibration would have stored it: every
// camera's residual RMS set to `rms_px` (the check's thresholds derive
// from it), and the board it was calibrated with, the dataset's
// `target_path` as it is (back_from_front as calibrated = the file's: the
// simulator's file is its truth). Returns it.
Rig WriteStoredRig(const std::string& truth_path, double rms_px, const std::string& out_path,
                   const std::string& target_path) {
  Rig rig = ReadRigFile(truth_path);
  for (int c = 0; c < rig.num_cameras(); ++c)
    rig.provenance().residuals["cam" + std::to_string(c) + "_rms_px"] = rms_px;
  const Target board = ReadTargetFile(target_path);
  rig.provenance().target = CalibrationTarget{
      target_path,          board.corners_x(),       board.corners_y(),       board.square_size_mm(),
      board.double_sided(), board.back_from_front(), board.back_from_front(), board.back_from_front_sigma()};
  WriteRigFile(rig, out_path);
  return rig;
}

TEST(CheckCli, BadInputExitsTwoWithOneLineAndLeavesTheHistoryIntact) {
  const std::string dir = ::testing::TempDir() + "/check_cli_" + std::to_string(getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  // Eight fresh captures of the default rig, lasers off.
  Result r = RunCli("simulate --out " + dir + "/ds --seed 21 --calibration-captures 8 --no-scenes");
  ASSERT_EQ(r.code, 0) << r.err;
  // The stored rig: the true rig with the residuals a calibration would have
  // written (the check derives its thresholds from them).
  const Rig rig = WriteStoredRig(dir + "/ds/truth/rig.yaml", 0.2, dir + "/rig.yaml", dir + "/ds/target.yaml");
  const std::string db = dir + "/history.sqlite", report = dir + "/check.json";
  auto check = [&](const std::string& captures, const std::string& rig_path) {
    return RunCli("check --rig " + rig_path + " --captures " + captures + " --target " + dir +
                  "/ds/target.yaml --history-db " + db + " --report " + report);
  };
  // One good run makes the history.
  r = check(dir + "/ds", dir + "/rig.yaml");
  ASSERT_NE(r.code, 2) << r.err;
  ASSERT_EQ(ReadDb(db).integrity, "ok");
  ASSERT_EQ(ReadDb(db).runs, 1);
  {  // What the night used: the rig file by absolute path and by zlib's
     // CRC-32 of its bytes, and the board as calibrated (the stored rig
     // records it).
    const std::string bytes = Bytes(dir + "/rig.yaml");
    char crc[16];
    std::snprintf(crc, sizeof crc, "%08lx",
                  crc32(crc32(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(bytes.data()), uInt(bytes.size())));
    const DbState s = ReadDb(db);
    EXPECT_EQ(s.last_rig_path, fs::canonical(dir + "/rig.yaml").string());
    EXPECT_EQ(s.last_rig_file, s.last_rig_path);                      // one path for one file, in both tables
    EXPECT_EQ(s.last_captures, fs::canonical(dir + "/ds").string());  // as typed: "<TempDir>/" + "/check_cli_..."
    EXPECT_EQ(s.last_rig_crc32, crc);
    EXPECT_EQ(s.last_board, "as calibrated");

    // The CRC is of the bytes the rig was parsed from, read once: it was
    // taken by a second read a moment after the parse, so a rig file
    // replaced in between was fingerprinted as the new one, and a rig given
    // as a pipe (read once, then gone) had none. A pipe shows it: its one
    // read is both the rig and the CRC.
    const std::string fifo = dir + "/rig_once.fifo", pipe_db = dir + "/history_pipe.sqlite";
    ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
    std::thread writer([&] {
      // Non-blocking open until the check opens the pipe to read it (a
      // check that never does must not hang the test).
      int fd = -1;
      for (int tries = 0; tries < 1200 && fd < 0; ++tries) {
        fd = open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
        if (fd < 0) std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
      if (fd < 0) return;
      fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) & ~O_NONBLOCK);
      for (size_t done = 0; done < bytes.size();) {
        const ssize_t n = write(fd, bytes.data() + done, bytes.size() - done);
        if (n <= 0) break;
        done += static_cast<size_t>(n);
      }
      close(fd);
    });
    const Result piped = RunCli("check --rig " + fifo + " --captures " + dir + "/ds --target " + dir +
                                "/ds/target.yaml --history-db " + pipe_db);
    writer.join();
    EXPECT_NE(piped.code, 2) << piped.err;
    EXPECT_EQ(ReadDb(pipe_db).last_rig_crc32, crc);
    fs::remove(fifo);
  }
  const std::string db_bytes = Bytes(db);
  fs::remove(report);

  // A copy of the good captures to break.
  auto copy = [&](const std::string& name) {
    const std::string d = dir + "/" + name;
    fs::copy(dir + "/ds/calibration", d, fs::copy_options::recursive);
    return d;
  };
  auto expect_refused = [&](const Result& res, const std::string& must_name, const char* what) {
    EXPECT_EQ(res.code, 2) << what << ": " << res.out << res.err;
    // Progress goes to stderr too; the reason is one line, the last.
    const std::string last = LastLine(res.err);
    EXPECT_EQ(last.rfind("stereorig check: ", 0), 0u) << what << ": " << res.err;
    EXPECT_EQ(Occurrences(res.err, "stereorig check: "), 1) << what << ": " << res.err;
    EXPECT_NE(last.find(must_name), std::string::npos) << what << ": " << res.err;
    EXPECT_FALSE(fs::exists(report)) << what;
    const DbState s = ReadDb(db);
    EXPECT_EQ(s.integrity, "ok") << what;
    EXPECT_EQ(s.runs, 1) << what;
    EXPECT_EQ(Bytes(db), db_bytes) << what << ": the history changed";
  };

  {  // A rig file given as a pipe (`--rig <(cat rig.yaml)`) without
     // --history-db: the history's default place, beside the rig file, is
     // /dev/fd/; it failed only after the whole check ("verdict: ok", then
     // exit 2). Refused before anything is read.
    const std::string fifo = dir + "/rig.fifo";
    ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
    const Result piped = RunCli("check --rig " + fifo + " --captures " + dir + "/ds --target " + dir +
                                "/ds/target.yaml --report " + report);
    EXPECT_EQ(piped.code, 2) << piped.err;
    EXPECT_EQ(Lines(piped.err), 1) << piped.err;
    EXPECT_NE(piped.err.find("--rig: " + fifo +
                             " is a pipe, with no folder for the history beside it: give "
                             "--history-db"),
              std::string::npos)
        << piped.err;
    EXPECT_FALSE(fs::exists(report));
    fs::remove(fifo);
  }
  {  // A rig file without a calibration's residuals (the simulator's truth
     // rig), or a captures folder that is not there: named before the
     // target's detection starts (its progress line), in one line. Before,
     // the first was named by the captures folder, after the detection.
    const std::string truth = dir + "/ds/truth/rig.yaml";
    Result no_residuals = RunCli("check --rig " + truth + " --captures " + dir + "/ds --target " + dir +
                                 "/ds/target.yaml --history-db " + db + " --report " + report);
    expect_refused(no_residuals, truth + ": the rig file has no provenance.residuals.cam0_rms_px", "truth rig");
    EXPECT_EQ(Lines(no_residuals.err), 1) << no_residuals.err;
    Result no_captures = check(dir + "/no_such_captures", dir + "/rig.yaml");
    expect_refused(no_captures, dir + "/no_such_captures: no such captures folder", "no captures folder");
    EXPECT_EQ(Lines(no_captures.err), 1) << no_captures.err;
  }
  {  // Another board's target file (squares of 9.18 mm; the rig was
     // calibrated with the 9 mm one): refused before the detection, in one
     // line naming both boards. Before, it read as every module measuring
     // the board 2 % small, and every camera changed.
    std::ifstream in(dir + "/ds/target.yaml");
    std::stringstream text;
    text << in.rdbuf();
    std::string other = text.str();
    const size_t at = other.find("square_size_mm: 9\n");
    ASSERT_NE(at, std::string::npos) << other;
    other.replace(at, 17, "square_size_mm: 9.18");
    const std::string other_path = dir + "/other_board.yaml";
    std::ofstream(other_path) << other;
    const Result r = RunCli("check --rig " + dir + "/rig.yaml --captures " + dir + "/ds --target " + other_path +
                            " --history-db " + db + " --report " + report);
    expect_refused(r,
                   other_path + ": a board of 11x9 inner corners of 9.18 mm, double-sided, but " + dir +
                       "/rig.yaml was calibrated with one of 11x9 inner corners of 9 mm, double-sided",
                   "another board");
    EXPECT_EQ(Lines(r.err), 1) << r.err;
    // Another plate (0.5 mm thicker): refused too, in one line.
    std::string plate = text.str();
    const size_t tz = plate.find("[0, 0, -1, 5]");
    ASSERT_NE(tz, std::string::npos) << plate;
    plate.replace(tz, 13, "[0, 0, -1, 5.5]");
    std::ofstream(dir + "/other_plate.yaml") << plate;
    const Result p = RunCli("check --rig " + dir + "/rig.yaml --captures " + dir + "/ds --target " + dir +
                            "/other_plate.yaml --history-db " + db + " --report " + report);
    expect_refused(p, dir + "/other_plate.yaml: its back_from_front is 0.5000 mm and 0.0000 deg from the one filed",
                   "another plate");
    EXPECT_EQ(Lines(p.err), 1) << p.err;
    // A rig file without the record (an older stereorig's) cannot tell
    // another board from the record. Against this file every figure holds
    // with the board's print at the size every module measures it, 2 %
    // off the file, and the board as a solid misses: refused as the
    // board's print in one line naming the file, with the board's size and
    // the note (it was judged "recalibrate", exit 1, every module flagged:
    // recalibrated against this file, the rig would take the 2 %).
    Rig old = rig;
    old.provenance().target.reset();
    WriteRigFile(old, dir + "/old_rig.yaml");
    const std::string old_report = dir + "/old_check.json";
    const Result print = RunCli("check --rig " + dir + "/old_rig.yaml --captures " + dir + "/ds --target " +
                                other_path + " --history-db " + dir + "/old_history.sqlite --report " + old_report);
    expect_refused(print,
                   other_path + ": the board's print is not its file's size: every module measures the board 1.9",
                   "an older rig's night against another board's file");
    EXPECT_NE(print.err.find("the rig file records no calibration target"), std::string::npos) << print.err;
    EXPECT_FALSE(fs::exists(old_report));
    // With the board's own file the night is judged, with the target
    // file's back_from_front, and a note says so. Its own history.
    const Result judged = RunCli("check --rig " + dir + "/old_rig.yaml --captures " + dir + "/ds --target " + dir +
                                 "/ds/target.yaml --history-db " + dir + "/old_history.sqlite --report " + old_report);
    EXPECT_NE(judged.code, 2) << judged.err;
    EXPECT_NE(judged.out.find("note: the rig file records no calibration target"), std::string::npos) << judged.out;
    std::ifstream f(old_report);
    const nlohmann::json j = nlohmann::json::parse(f, nullptr, false);
    ASSERT_TRUE(j.is_object()) << old_report;
    EXPECT_EQ(j["target"]["as_calibrated"], false) << j.dump(2);
    EXPECT_EQ(j["target"]["back_from_front_as_calibrated"], false) << j.dump(2);
    EXPECT_TRUE(j["target"]["calibrated_with"].is_null()) << j.dump(2);
    EXPECT_TRUE(j["target"]["note"].is_string()) << j.dump(2);
    EXPECT_TRUE(j["board_size_note"].is_null()) << j.dump(2);
  }
  {  // A coverage factor that is not finite, or so large it would pass any
     // drift (inf was accepted, a verdict "ok" with infinite thresholds
     // written into the history), and a check's options with --history,
     // which reads the history alone (they were ignored).
    for (const char* k : {"inf", "1e9", "0"})
      expect_refused(RunCli("check --rig " + dir + "/rig.yaml --captures " + dir + "/ds --target " + dir +
                            "/ds/target.yaml --history-db " + db + " --report " + report + " --k-sigma " + k),
                     "--k-sigma: must be in (0, 10]", k);
    expect_refused(RunCli("check --history --history-db " + db + " --report " + report),
                   "--report: does not apply with --history", "--history with --report");
    // A --rig that is not there, with --history: it printed the history
    // found beside it (or at --history-db) and exited 0.
    fs::copy_file(db, dir + "/check-history.sqlite", fs::copy_options::overwrite_existing);
    expect_refused(RunCli("check --history --rig " + dir + "/no_such_rig.yaml"), dir + "/no_such_rig.yaml",
                   "--history with a missing --rig");
    expect_refused(RunCli("check --history --rig " + dir + "/no_such_rig.yaml --history-db " + db),
                   dir + "/no_such_rig.yaml", "--history with a missing --rig and --history-db");
    fs::remove(dir + "/check-history.sqlite");
  }
  {  // Bytes of another format (a JPEG's start) named cam1.png: named so, in
     // one line (before, the decoder's own complaint could come first).
    const std::string d = copy("jpeg_named_png");
    std::ofstream(d + "/003/cam1.png", std::ios::binary | std::ios::trunc) << "\xff\xd8\xff\xe0 a JPEG's start";
    expect_refused(check(d, dir + "/rig.yaml"), "003/cam1.png: is not a PNG file, though named .png", "JPEG bytes");
  }
  {  // A pipe named cam1.png (a capture tool writing through one): refused
     // in one line, never opened. Before, the CRC of the night's images
     // opened it first and blocked until a writer came, so a nightly timer
     // hung. A watchdog opening the pipe to write, which succeeds only while
     // a reader holds it open, tells a check that opened it (and lets it go
     // on) from one that did not.
    const std::string d = copy("pipe_image"), pipe = d + "/003/cam1.png";
    fs::remove(pipe);
    ASSERT_EQ(mkfifo(pipe.c_str(), 0600), 0);
    std::atomic<bool> done{false}, opened{false};
    std::thread watchdog([&] {
      while (!done) {
        if (const int fd = open(pipe.c_str(), O_WRONLY | O_NONBLOCK); fd >= 0) opened = true, close(fd);
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
    });
    const Result r = check(d, dir + "/rig.yaml");
    done = true;
    watchdog.join();
    EXPECT_FALSE(opened) << "the check opened the pipe to read it";
    expect_refused(r, "003/cam1.png: is not a regular file", "a pipe as an image");
  }
  {  // Empty images (0 bytes: a failed write) in more captures than the
     // night can spare: each costs its capture, as a missing one does
     // (ExchangedCables...AMissingImage...), and the refusal names them.
     // Before, the first empty one refused the night as unreadable.
    const std::string d = copy("empty_images");
    for (const char* capture : {"001", "002", "003", "004", "005", "006"})
      std::ofstream(d + "/" + capture + "/cam1.png", std::ios::binary | std::ios::trunc).close();
    expect_refused(check(d, dir + "/rig.yaml"), "001/cam1.png: missing or empty (each capture needs camK.png",
                   "empty images");
  }
  {  // A corrupt (truncated, unreadable) image.
    const std::string d = copy("corrupt");
    const std::string bad = d + "/003/cam1.png";
    const std::string png = Bytes(bad);
    std::ofstream(bad, std::ios::binary | std::ios::trunc) << png.substr(0, 40);
    expect_refused(check(d, dir + "/rig.yaml"), "003/cam1.png", "corrupt image");
  }
  {  // One image of the wrong size.
    const std::string d = copy("wrong_size");
    cv::imwrite(d + "/005/cam2.png", cv::Mat(480, 640, CV_8UC1, cv::Scalar(40)));
    expect_refused(check(d, dir + "/rig.yaml"), "005/cam2.png", "wrong-size image");
  }
  {  // The wrong-size image in the first capture: held to the rig's size,
     // it is the one named (held to the first capture's, the right image
     // of the next capture was blamed: "001/cam2.png: ... 752x582, but
     // cam2's other images are 640x480").
    const std::string d = copy("wrong_size_first");
    cv::imwrite(d + "/000/cam2.png", cv::Mat(480, 640, CV_8UC1, cv::Scalar(40)));
    expect_refused(check(d, dir + "/rig.yaml"), "000/cam2.png: 640x480, but the rig's cam2 is 752x582",
                   "wrong-size first image");
  }
  {  // A 16-bit image (a 12-bit camera's, in the low bits): imread's grey
     // conversion took its high byte, a nearly black image.
    const std::string d = copy("sixteen_bit");
    cv::Mat wide;
    cv::imread(d + "/002/cam0.png", cv::IMREAD_GRAYSCALE).convertTo(wide, CV_16U, 16.0);
    cv::imwrite(d + "/002/cam0.png", wide);
    expect_refused(check(d, dir + "/rig.yaml"), "002/cam0.png: must be an 8-bit single-channel", "16-bit image");
  }
  {  // Captures from another rig whose camera 3 is another camera (half the pixels).
    const std::string d = copy("other_camera");
    for (const auto& capture : fs::directory_iterator(d)) {
      const std::string p = (capture.path() / "cam3.png").string();
      cv::Mat half;
      cv::resize(cv::imread(p, cv::IMREAD_GRAYSCALE), half, cv::Size(376, 291), 0, 0, cv::INTER_AREA);
      cv::imwrite(p, half);
    }
    expect_refused(check(d, dir + "/rig.yaml"), "another rig", "captures of other cameras");
  }
  {  // Captures from a rig with more cameras (a third module).
    const std::string d = copy("more_cameras");
    for (const auto& capture : fs::directory_iterator(d)) {
      fs::copy_file(capture.path() / "cam0.png", capture.path() / "cam4.png");
      fs::copy_file(capture.path() / "cam1.png", capture.path() / "cam5.png");
    }
    expect_refused(check(d, dir + "/rig.yaml"), "but the rig has 4 cameras", "captures of a larger rig");
  }
  {  // A camera index no int holds (std::stoi threw out_of_range here, past
     // RunCommand: the process aborted).
    const std::string d = copy("huge_index");
    for (const auto& capture : fs::directory_iterator(d))
      fs::copy_file(capture.path() / "cam0.png", capture.path() / "cam12345678901.png");
    expect_refused(check(d, dir + "/rig.yaml"), "a camera index beyond any rig, but the rig has 4 cameras",
                   "a camera index beyond any rig");
  }
  {  // A capture folder named by a time stamp, a number no int holds:
     // std::stoi threw out_of_range, and the process aborted (exit 134).
    const std::string d = copy("stamped_capture");
    fs::rename(d + "/007", d + "/20261207153000");
    expect_refused(check(d, dir + "/rig.yaml"), d + "/20261207153000: a capture folder's number must be under 10^9",
                   "a time-stamped capture");
  }
  {  // Two folders of one capture index (003 and 0003): their views were
     // merged into one capture of two board poses, and the night judged
     // "ok" on one capture fewer than it has.
    const std::string d = copy("one_index_twice");
    fs::rename(d + "/007", d + "/0003");
    expect_refused(check(d, dir + "/rig.yaml"), d + "/003: is capture 3, as " + d + "/0003 is",
                   "two folders of one capture");
  }
  {  // A negative projection uncertainty in the rig file (a standard
     // deviation, >= 0): squared into cam0's threshold, it made it 3.5 px
     // against 0.03, a check that could not fail, exit 0. Refused as the
     // rig file's; so is a negative residual RMS (it was said missing).
    for (const char* key : {"cam0_projection_center_px", "cam0_rms_px"}) {
      Rig bad = rig;
      auto& section = std::string(key) == "cam0_rms_px" ? bad.provenance().residuals : bad.provenance().uncertainties;
      section[key] = -1;
      WriteRigFile(bad, dir + "/negative_rig.yaml");
      expect_refused(check(dir + "/ds", dir + "/negative_rig.yaml"),
                     "/negative_rig.yaml: provenance." +
                         std::string(std::string(key) == "cam0_rms_px" ? "residuals." : "uncertainties.") + key +
                         ": must be >= 0, got -1",
                     key);
    }
  }
  {  // A residual RMS of exactly 0 (valid in the file, >= 0): the check
     // weights corners by 1 / rms^2, so it cannot use it, and says so, in one
     // line before the detection. Before, the rig file was said to have no
     // such residual, which it has.
    Rig zero = rig;
    zero.provenance().residuals["cam0_rms_px"] = 0;
    const std::string zero_path = dir + "/zero_rms_rig.yaml";
    WriteRigFile(zero, zero_path);
    const Result res = check(dir + "/ds", zero_path);
    expect_refused(res, zero_path + ": the rig file's provenance.residuals.cam0_rms_px is 0 px", "a zero RMS");
    EXPECT_EQ(Lines(res.err), 1) << res.err;
    EXPECT_EQ(res.err.find("has no"), std::string::npos) << res.err;
  }
  {  // The right images with the rig file of another rig: every camera's
     // focal length 20% longer and its centre 40 px away.
    std::vector<Camera> cameras;
    for (int c = 0; c < rig.num_cameras(); ++c) {
      std::vector<double> p = rig.camera(c).intrinsics();
      p[0] *= 1.2, p[1] *= 1.2, p[2] += 40;
      cameras.emplace_back(rig.camera(c).lensmodel_name(), p, rig.camera(c).imager_width_px(),
                           rig.camera(c).imager_height_px());
    }
    Rig other(cameras, rig.camera_names(), rig.modules(), std::vector<Pose>{rig.S(0, 0), rig.S(0, 1)});
    other.provenance() = rig.provenance();
    WriteRigFile(other, dir + "/other_rig.yaml");
    expect_refused(check(dir + "/ds", dir + "/other_rig.yaml"), "another rig", "another rig's file");
  }
  {  // A history path that is not a database: refused, the file untouched.
    const std::string not_db = dir + "/notes.txt";
    std::ofstream(not_db) << "not a database\n";
    r = RunCli("check --rig " + dir + "/rig.yaml --captures " + dir + "/ds --target " + dir +
               "/ds/target.yaml --history-db " + not_db + " --report " + report);
    EXPECT_FALSE(fs::exists(report));
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_EQ(Occurrences(r.err, "stereorig check: "), 1) << r.err;
    EXPECT_NE(LastLine(r.err).find(not_db), std::string::npos) << r.err;
    EXPECT_EQ(Bytes(not_db), "not a database\n");
  }
  {  // A history another process holds (a write lock: what root, as in CI,
     // can make of the read-only file a user's walkthrough tried as nobody):
     // refused before the detection, no report, the history as it was.
     // Before, the night ran, printed its verdict, wrote its report, and
     // then failed to record it: exit 2 with a report on disk.
    sqlite3* other = nullptr;
    ASSERT_EQ(sqlite3_open(db.c_str(), &other), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(other, "BEGIN IMMEDIATE;", nullptr, nullptr, nullptr), SQLITE_OK);
    r = check(dir + "/ds", dir + "/rig.yaml");
    sqlite3_exec(other, "ROLLBACK;", nullptr, nullptr, nullptr);
    sqlite3_close(other);
    expect_refused(r, "cannot be written", "a history another process holds");
    EXPECT_EQ(r.err.find("detecting"), std::string::npos) << r.err;
  }
  {  // A report named as the rig file (it would replace the rig file with
     // JSON), or into a folder that is not there (it failed after the
     // detection): refused before any work, the rig file and history intact.
    const std::string rig_bytes = Bytes(dir + "/rig.yaml");
    auto check_report = [&](const std::string& report_path) {
      return RunCli("check --rig " + dir + "/rig.yaml --captures " + dir + "/ds --target " + dir +
                    "/ds/target.yaml --history-db " + db + " --report " + report_path);
    };
    r = check_report(dir + "/rig.yaml");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(LastLine(r.err).find("rig.yaml: is the rig file (--rig)"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("detecting"), std::string::npos) << r.err;  // before the detection's progress
    EXPECT_EQ(Bytes(dir + "/rig.yaml"), rig_bytes);
    r = check_report(dir + "/missing/check.json");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(LastLine(r.err).find("check.json: its folder does not exist"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("detecting"), std::string::npos) << r.err;
    EXPECT_EQ(Bytes(db), db_bytes);
    // Without --history-db the history's default path is what is named.
    r = RunCli("check --rig " + dir + "/rig.yaml --captures " + dir + "/ds --target " + dir +
               "/ds/target.yaml --report " + dir + "/check-history.sqlite");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(LastLine(r.err).find("(by default beside the rig file"), std::string::npos) << r.err;
  }
  fs::remove_all(dir);
}

// The report's lists say what the check found (docs/verify-and-check.md,
// "The report"): flagged_cameras and flagged_modules every camera and module
// named (moved_cameras and moved_modules, their old names, the same: an
// alarm built on them fires for a drifted lens too), camera_changes' kind
// what explains each camera, and a two-module rig's closure names both
// modules and says it cannot tell which one changed. Before, a shift of
// module 0 read "module 1 moved or a lens changed".
//
// The stored rig: the simulator's truth with 0.03 px residuals, what a
// calibrated rig's rendered corners read (stage 1: 0.022 px, a night:
// 0.03 px). Measured: camera 2's focal length +0.5 % leaves 0.120 px with a
// new pose and 0.023 px with a new lens, camera 2 turned 0.05 deg 0.023 and
// 0.079 px, against a threshold of 0.034 px: each kind by a factor of 2.3 or
// more; module 0 shifted 0.1 mm reads a closure of 0.101 mm against
// 0.0097 mm.
TEST(CheckCli, TheReportListsEveryNamedCameraAndModuleAndWhatExplainsEach) {
  const std::string dir = ::testing::TempDir() + "/check_cli_kinds_" + std::to_string(getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  Result r = RunCli("simulate --out " + dir + "/unmoved --seed 21 --calibration-captures 1 --no-scenes");
  ASSERT_EQ(r.code, 0) << r.err;
  WriteStoredRig(dir + "/unmoved/truth/rig.yaml", 0.03, dir + "/rig.yaml", dir + "/unmoved/target.yaml");
  // A night of 8 captures after `bump`, checked: its report.
  auto night = [&](const std::string& name, const std::string& bump) {
    const std::string captures = dir + "/" + name, report = dir + "/" + name + ".json";
    Result sim = RunCli("simulate --out " + captures + " --seed 21 --calibration-captures 8 --no-scenes " + bump);
    EXPECT_EQ(sim.code, 0) << sim.err;
    Result checked = RunCli("check --rig " + dir + "/rig.yaml --captures " + captures + " --target " + captures +
                            "/target.yaml --history-db " + dir + "/history.sqlite --report " + report);
    EXPECT_EQ(checked.code, 1) << checked.out << checked.err;
    std::ifstream f(report);
    return nlohmann::json::parse(f, nullptr, false);
  };
  const nlohmann::json lens = night("focal", "--bump-camera 2 --bump-focal-percent 0.5");
  ASSERT_TRUE(lens.is_object());
  EXPECT_EQ(lens["flagged_cameras"], nlohmann::json::array({2})) << lens.dump(2);
  EXPECT_EQ(lens["moved_cameras"], nlohmann::json::array({2})) << lens.dump(2);
  ASSERT_EQ(lens["camera_changes"].size(), 1u) << lens.dump(2);
  EXPECT_EQ(lens["camera_changes"][0]["kind"], "lens");
  // The board measured with: the rig file's record (check_target.h), here
  // the dataset's own file.
  EXPECT_EQ(lens["target"]["as_calibrated"], true) << lens.dump(2);
  EXPECT_EQ(lens["target"]["calibrated_with"], dir + "/unmoved/target.yaml") << lens.dump(2);
  EXPECT_EQ(lens["target"]["back_from_front_as_calibrated"], true) << lens.dump(2);
  EXPECT_EQ(lens["target"]["calibrated_vs_file_mm"], 0.0) << lens.dump(2);
  EXPECT_EQ(lens["target"]["file_vs_filed_mm"], 0.0) << lens.dump(2);
  EXPECT_TRUE(lens["target"]["note"].is_null()) << lens.dump(2);
  const nlohmann::json turned = night("turned", "--bump-camera 2 --bump-rotation-deg 0.05");
  ASSERT_TRUE(turned.is_object());
  EXPECT_EQ(turned["flagged_cameras"], nlohmann::json::array({2})) << turned.dump(2);
  EXPECT_EQ(turned["moved_cameras"], nlohmann::json::array({2})) << turned.dump(2);
  ASSERT_EQ(turned["camera_changes"].size(), 1u) << turned.dump(2);
  EXPECT_EQ(turned["camera_changes"][0]["kind"], "moved");
  // The pose fit's turn, against the simulator's 0.05 deg. Corners to a few
  // hundredths of a px on ~400 of them fix a turn to ~1e-4 deg (0.03 px /
  // (1000 px sqrt(400)) rad); calibrated-rig nights read 0.1 to 3 deg to
  // 0.001 deg (docs/verify-and-check.md). The bound, a tenth of the turn,
  // is wide of both: it asks that the figure is the camera's turn, not
  // that it is as good as it reads.
  EXPECT_NEAR(turned["camera_changes"][0]["turned_deg"].get<double>(), 0.05, 0.005) << turned.dump(2);
  EXPECT_NE(turned["explanation"].get<std::string>().find("camera 2 moved: turned 0.05"), std::string::npos)
      << turned.dump(2);
  EXPECT_NE(turned["explanation"].get<std::string>().find("[module 1's left camera]"), std::string::npos)
      << turned.dump(2);
  EXPECT_TRUE(lens["camera_changes"][0]["turned_deg"].is_number()) << lens.dump(2);  // fitted, if not what changed
  EXPECT_EQ(turned["flagged_modules"], nlohmann::json::array());
  {
    // The same night with its stdout lost (a full log disk): the drift still
    // reads as a failed check (1), not as bad input (2), after one line
    // saying the output was lost; its report is written.
    const std::string err = dir + "/full.err", report = dir + "/full.json";
    const int status = std::system((kBin + " check --rig " + dir + "/rig.yaml --captures " + dir + "/turned --target " +
                                    dir + "/turned/target.yaml --history-db " + dir + "/history.sqlite --report " +
                                    report + " >/dev/full 2>" + err)
                                       .c_str());
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 1) << Bytes(err);
    EXPECT_EQ(LastLine(Bytes(err)), "stereorig check: standard output: cannot be written: No space left on device");
    EXPECT_TRUE(fs::exists(report));
  }
  const nlohmann::json shifted = night("shifted", "--bump-module 0 --bump-translation-mm 0.1");
  ASSERT_TRUE(shifted.is_object());
  EXPECT_EQ(shifted["explanation"], "module 0 and module 1 disagree: one moved or a lens changed");
  EXPECT_EQ(shifted["flagged_modules"], nlohmann::json::array({0, 1})) << shifted.dump(2);
  EXPECT_EQ(shifted["moved_modules"], nlohmann::json::array({0, 1})) << shifted.dump(2);
  EXPECT_EQ(shifted["closure_modules"], nlohmann::json::array({0, 1})) << shifted.dump(2);
  EXPECT_EQ(shifted["closure_which_unknown"], true) << shifted.dump(2);
  EXPECT_EQ(shifted["flagged_cameras"], nlohmann::json::array()) << shifted.dump(2);
  fs::remove_all(dir);
}

// A simulated night of the unmoved rig (seed 21, 8 captures) in dir/ds, the
// rig as stored (0.03 px residuals) in dir/rig.yaml; its captures' names,
// sorted (fewer than 8 if the simulation failed, which it says).
std::vector<std::string> UnmovedNight(const std::string& dir) {
  fs::remove_all(dir);
  fs::create_directories(dir);
  const Result r = RunCli("simulate --out " + dir + "/ds --seed 21 --calibration-captures 8 --no-scenes");
  EXPECT_EQ(r.code, 0) << r.err;
  if (r.code != 0) return {};
  WriteStoredRig(dir + "/ds/truth/rig.yaml", 0.03, dir + "/rig.yaml", dir + "/ds/target.yaml");
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir + "/ds/calibration"))
    if (e.is_directory()) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// How a rig changed since it was stored (WriteChangedRig): every lens's
// focal length longer by focal_percent, some cameras' lenses besides
// (camera -> focal %, principal point dx, dy px), every translation (each
// baseline, S) longer by the factor `scale`, module 1 moved by
// module1_offset_mm (in module 0's frame).
struct RigChange {
  double focal_percent = 0;
  std::map<int, std::array<double, 3>> lenses = {};
  double scale = 1;
  Eigen::Vector3d module1_offset_mm = Eigen::Vector3d::Zero();
};

// `stored` (a rig file) as it was before `change`, written to `out_path`:
// the captures of the rig as it is (its truth) then read the change.
void WriteChangedRig(const std::string& stored, const std::string& out_path, const RigChange& change) {
  const Rig rig = ReadRigFile(stored);
  std::vector<Camera> cameras;
  for (int c = 0; c < rig.num_cameras(); ++c) {
    const Camera& cam = rig.camera(c);
    std::array<double, 3> lens = {0, 0, 0};
    if (change.lenses.count(c)) lens = change.lenses.at(c);
    std::vector<double> intrinsics = cam.intrinsics();
    const double focal = (1 + change.focal_percent / 100) * (1 + lens[0] / 100);
    intrinsics[0] /= focal;
    intrinsics[1] /= focal;
    intrinsics[2] -= lens[1];
    intrinsics[3] -= lens[2];
    cameras.emplace_back(cam.lensmodel_name(), intrinsics, cam.imager_width_px(), cam.imager_height_px());
  }
  std::vector<StereoModule> modules = rig.modules();
  for (StereoModule& m : modules)
    m.right_from_left = Pose(m.right_from_left.rotation(), m.right_from_left.translation_mm() / change.scale);
  std::vector<Pose> module0_from_module;
  for (int m = 0; m < rig.num_modules(); ++m)
    module0_from_module.push_back(Pose(
        rig.S(0, m).rotation(),
        rig.S(0, m).translation_mm() / change.scale - (m == 1 ? change.module1_offset_mm : Eigen::Vector3d::Zero())));
  Rig changed(cameras, rig.camera_names(), modules, module0_from_module);
  changed.provenance() = rig.provenance();
  WriteRigFile(changed, out_path);
}

// A change every camera shares: all four focal lengths 0.1 % longer than
// stored (thermal drift) read "camera 0 changed: neither ...; camera 2
// changed: neither ..." and a note that every camera fails, two cameras
// named as if the others had not changed; the rig 0.2 % larger (every
// baseline and S) read so too. Said now as what they are, nothing named
// alone. Each fails every camera's figure by ~0.2 px against ~0.03 px, and
// the fitted sizes are held to a tenth of the change, where the night's
// ~1600 corners at 0.03 px fix them to ~1e-5.
TEST(CheckCli, EveryLensDriftedAlikeOrTheRigsScaleIsSaidNotNamedAsTwoCameras) {
  const std::string dir = ::testing::TempDir() + "/check_cli_alike_" + std::to_string(getpid());
  const std::vector<std::string> names = UnmovedNight(dir);
  ASSERT_GE(names.size(), 8u);
  auto check = [&](const std::string& rig, const std::string& report) {
    const Result r = RunCli("check --rig " + rig + " --captures " + dir + "/ds/calibration --target " + dir +
                            "/ds/target.yaml --history-db " + dir + "/history.sqlite --report " + report);
    EXPECT_EQ(r.code, 1) << r.out << r.err;
    std::ifstream f(report);
    return nlohmann::json::parse(f, nullptr, false);
  };
  WriteChangedRig(dir + "/rig.yaml", dir + "/thermal.yaml", {.focal_percent = 0.1});
  const nlohmann::json thermal = check(dir + "/thermal.yaml", dir + "/thermal.json");
  ASSERT_TRUE(thermal.is_object());
  const std::string said = thermal["explanation"];
  EXPECT_EQ(said.find("every camera's lens changed alike: focal length +0.10"), 0u) << said;
  EXPECT_EQ(said.find("neither"), std::string::npos) << said;
  EXPECT_EQ(thermal["flagged_cameras"], nlohmann::json::array({0, 1, 2, 3})) << thermal.dump(2);
  EXPECT_EQ(thermal["camera_changes"], nlohmann::json::array()) << thermal.dump(2);
  ASSERT_TRUE(thermal["shared_lens_change"].is_object()) << thermal.dump(2);
  EXPECT_NEAR(thermal["shared_lens_change"]["focal_percent"].get<double>(), 0.1, 0.01) << thermal.dump(2);

  WriteChangedRig(dir + "/rig.yaml", dir + "/larger.yaml", {.scale = 1.002});
  const nlohmann::json larger = check(dir + "/larger.yaml", dir + "/larger.json");
  ASSERT_TRUE(larger.is_object());
  const std::string scale_said = larger["explanation"];
  EXPECT_EQ(scale_said.find("the rig's scale against the board's changed: every module measures the board 0.1"), 0u)
      << scale_said;
  EXPECT_EQ(larger["flagged_cameras"], nlohmann::json::array()) << larger.dump(2);
  EXPECT_EQ(larger["flagged_modules"], nlohmann::json::array({0, 1})) << larger.dump(2);
  ASSERT_TRUE(larger["shared_scale"].is_number()) << larger.dump(2);
  EXPECT_NEAR(larger["shared_scale"].get<double>(), 1 / 1.002, 0.0002) << larger.dump(2);
  EXPECT_EQ(larger["shared_scale_print_only"], false) << larger.dump(2);
  fs::remove_all(dir);
}

// A change every camera shares besides one camera's own: every principal
// point +0.5 px, camera 0's +0.8 px. The shared fit, pulled by camera 0,
// explained no night, and against the unchanged rig two cameras read
// "neither" (cameras 0 and 3 on the demo's night, camera 3 unchanged but
// for the shared change). Fitted without
// camera 0 the shared change explains the rest, and camera 0 is named
// against them with it applied: its own +0.3 px. The changes are 10 to 25
// times the 0.03 px corners' noise; the fitted sizes are held to a tenth
// (~1600 corners fix them to a few thousandths).
TEST(CheckCli, ASharedLensChangeBesidesOneCamerasOwnNamesThatCameraAlone) {
  const std::string dir = ::testing::TempDir() + "/check_cli_besides_" + std::to_string(getpid());
  const std::vector<std::string> names = UnmovedNight(dir);
  ASSERT_GE(names.size(), 8u);
  WriteChangedRig(dir + "/rig.yaml", dir + "/besides.yaml",
                  {.lenses = {{0, {0, 0.8, 0}}, {1, {0, 0.5, 0}}, {2, {0, 0.5, 0}}, {3, {0, 0.5, 0}}}});
  const Result r = RunCli("check --rig " + dir + "/besides.yaml --captures " + dir + "/ds/calibration --target " + dir +
                          "/ds/target.yaml --history-db " + dir + "/history.sqlite --report " + dir + "/besides.json");
  EXPECT_EQ(r.code, 1) << r.out << r.err;
  std::ifstream f(dir + "/besides.json");
  const nlohmann::json j = nlohmann::json::parse(f, nullptr, false);
  ASSERT_TRUE(j.is_object());
  const std::string said = j["explanation"];
  EXPECT_EQ(said.find("every camera's lens changed alike: focal length "), 0u) << said;
  EXPECT_NE(said.find(", and camera 0 besides"), std::string::npos) << said;
  EXPECT_EQ(said.find("neither"), std::string::npos) << said;
  ASSERT_TRUE(j["shared_lens_change"].is_object()) << j.dump(2);
  EXPECT_NEAR(j["shared_lens_change"]["principal_point_px"][0].get<double>(), 0.5, 0.05) << j.dump(2);
  EXPECT_EQ(j["shared_lens_besides"], nlohmann::json::array({0})) << j.dump(2);
  EXPECT_EQ(j["flagged_cameras"], nlohmann::json::array({0, 1, 2, 3})) << j.dump(2);
  ASSERT_EQ(j["camera_changes"].size(), 1u) << j.dump(2);
  EXPECT_EQ(j["camera_changes"][0]["camera"], 0) << j.dump(2);
  // A principal point's shift reads, to first order, as a turn: "lens" or
  // "either", never "neither".
  EXPECT_TRUE(j["camera_changes"][0]["kind"] == "lens" || j["camera_changes"][0]["kind"] == "moved_or_lens")
      << j.dump(2);
  EXPECT_NEAR(j["camera_changes"][0]["principal_point_px"][0].get<double>(), 0.3, 0.03) << j.dump(2);
  fs::remove_all(dir);
}

// A module that moved as a whole while a lens of it changed: its cameras
// disagree with each other, so its closure was not judged, and each was
// read against the other module alone. Camera 0's principal point +1 px
// with module 1 0.5 mm off read "camera 0 moved: ... shifted 0.506 mm;
// camera 1 moved: ... shifted 0.495 mm", camera 1 unchanged, the modules'
// offset unnamed; a sibling rig's file (cam0's focal length -0.58 % and
// principal point +3.5 px, cam1's -4.5 px, module 1 1.5 mm off) read
// cameras 0 and 1 "neither", the offset unnamed. Both name the modules'
// disagreement now, with the shift, and only the lenses that changed, each
// with its change. The changes are 30 to 150 times the 0.03 px corners'
// noise; the fitted sizes are held to a tenth of the change (~1600 corners
// fix them to a few thousandths).
TEST(CheckCli, AModuleOffsetBesidesALensChangeNamesTheModulesAndTheLens) {
  const std::string dir = ::testing::TempDir() + "/check_cli_offset_" + std::to_string(getpid());
  const std::vector<std::string> names = UnmovedNight(dir);
  ASSERT_GE(names.size(), 8u);
  auto check = [&](const std::string& name, const RigChange& change) {
    WriteChangedRig(dir + "/rig.yaml", dir + "/" + name + ".yaml", change);
    const std::string report = dir + "/" + name + ".json";
    const Result r =
        RunCli("check --rig " + dir + "/" + name + ".yaml --captures " + dir + "/ds/calibration --target " + dir +
               "/ds/target.yaml --history-db " + dir + "/history.sqlite --report " + report);
    EXPECT_EQ(r.code, 1) << r.out << r.err;
    std::ifstream f(report);
    return nlohmann::json::parse(f, nullptr, false);
  };
  const nlohmann::json offset =
      check("offset", {.lenses = {{0, {0, 1, 0}}}, .module1_offset_mm = Eigen::Vector3d(0.5, 0, 0)});
  ASSERT_TRUE(offset.is_object());
  EXPECT_EQ(offset["flagged_cameras"], nlohmann::json::array({0})) << offset.dump(2);
  EXPECT_EQ(offset["closure_modules"], nlohmann::json::array({0, 1})) << offset.dump(2);
  ASSERT_EQ(offset["camera_changes"].size(), 1u) << offset.dump(2);
  // A principal point's shift reads, to first order, as a turn: "lens" or
  // "either" (moved_or_lens), never "moved" alone nor "neither".
  EXPECT_TRUE(offset["camera_changes"][0]["kind"] == "lens" || offset["camera_changes"][0]["kind"] == "moved_or_lens")
      << offset.dump(2);
  EXPECT_NEAR(offset["camera_changes"][0]["principal_point_px"][0].get<double>(), 1, 0.1) << offset.dump(2);
  ASSERT_EQ(offset["module_shifts"].size(), 1u) << offset.dump(2);
  EXPECT_NEAR(offset["module_shifts"][0]["shift_mm"].get<double>(), 0.5, 0.05) << offset.dump(2);
  EXPECT_NE(offset["explanation"].get<std::string>().find("module 0 and module 1 disagree"), std::string::npos)
      << offset.dump(2);
  // Module 1 moved, and the entry is module 0's (the one whose cameras
  // disagree, its lens): with two modules the shift is relative, and the
  // entry says so, not that module 0 moved.
  EXPECT_EQ(offset["module_shifts"][0]["module"], 0) << offset.dump(2);
  EXPECT_EQ(offset["module_shifts"][0]["relative_to"], nlohmann::json::array({1})) << offset.dump(2);
  EXPECT_EQ(offset["module_shifts"][0]["which_unknown"], true) << offset.dump(2);
  EXPECT_NE(offset["explanation"].get<std::string>().find(
                "module 0 moved against module 1, or module 1 against module 0, which the check cannot tell"),
            std::string::npos)
      << offset.dump(2);

  const nlohmann::json sibling = check("sibling", {.lenses = {{0, {-0.58, 3.5, 0}}, {1, {0, -4.5, 0}}},
                                                   .module1_offset_mm = Eigen::Vector3d(1.5, 0, 0)});
  ASSERT_TRUE(sibling.is_object());
  EXPECT_EQ(sibling["closure_modules"], nlohmann::json::array({0, 1})) << sibling.dump(2);
  ASSERT_EQ(sibling["camera_changes"].size(), 2u) << sibling.dump(2);
  for (const nlohmann::json& c : sibling["camera_changes"]) {
    EXPECT_TRUE(c["kind"] == "lens" || c["kind"] == "moved_or_lens") << sibling.dump(2);
    const int camera = c["camera"];
    EXPECT_NEAR(c["principal_point_px"][0].get<double>(), camera == 0 ? 3.5 : -4.5, 0.35) << sibling.dump(2);
  }
  ASSERT_EQ(sibling["module_shifts"].size(), 1u) << sibling.dump(2);
  EXPECT_NEAR(sibling["module_shifts"][0]["shift_mm"].get<double>(), 1.5, 0.15) << sibling.dump(2);
  fs::remove_all(dir);
}

// The capture images are inputs too: a --report or --history-db named like
// one of them would replace it. Refused before any work (no rig file nor
// target is read: neither exists), one line naming the path, the image
// byte-identical.
// One image from another capture (a camera triggered at another moment):
// it fits its own board pose, so the jump test keeps it, and through the
// all-camera pose it failed every camera's figure (14-93 px against ~0.03
// px) and named camera 1 changed, on an unmoved rig. It is set aside and
// named instead, and the night judged on the rest: ok. Its reading is
// hundreds of pixels (another board pose) against a bound of 10 times
// ~0.03 px, so the outcome does not hang on the simulated noise.
TEST(CheckCli, AViewFromAnotherCaptureIsSetAsideAndTheUnmovedRigPasses) {
  const std::string dir = ::testing::TempDir() + "/check_cli_moment_" + std::to_string(getpid());
  const std::vector<std::string> names = UnmovedNight(dir);
  ASSERT_GE(names.size(), 8u);
  Result r;
  const std::string captures = dir + "/swapped", report = dir + "/swapped.json";
  fs::copy(dir + "/ds/calibration", captures, fs::copy_options::recursive);
  fs::copy_file(captures + "/" + names[6] + "/cam1.png", captures + "/" + names[1] + "/cam1.png",
                fs::copy_options::overwrite_existing);
  r = RunCli("check --rig " + dir + "/rig.yaml --captures " + captures + " --target " + dir +
             "/ds/target.yaml --history-db " + dir + "/history.sqlite --report " + report);
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("set aside: capture " + names[1] + " cam1: off the capture's other views by "),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("taken at another moment than the capture's other views?"), std::string::npos) << r.out;
  std::ifstream f(report);
  const nlohmann::json j = nlohmann::json::parse(f, nullptr, false);
  ASSERT_TRUE(j.is_object());
  ASSERT_EQ(j["views_set_aside"].size(), 1u) << j.dump(2);
  const nlohmann::json& v = j["views_set_aside"][0];
  EXPECT_EQ(v["capture"], names[1]);
  EXPECT_EQ(v["camera"], 1);
  EXPECT_EQ(v["why"], "other_moment");
  EXPECT_TRUE(v.contains("whole_capture") && v["whole_capture"].is_null()) << j.dump(2);
  EXPECT_GT(v["off_px"].get<double>(), v["bound_px"].get<double>());
  EXPECT_EQ(j["verdict"], "ok") << j.dump(2);
  fs::remove_all(dir);
}

// A view seen nearly edge-on whose corners share one error, on the
// three-module ring (datasets/specs/ring3.yaml, seed 209's 8 captures, the
// true rig stored at a ring calibration's 0.022 px): capture 005's cam5
// sees the board 83 deg from face-on, and its image is shifted whole by
// (-0.10, -0.25) px, the error measured on such a view of another ring night
// (docs/verify-and-check.md: its corners fit their own pose and do not jump,
// and through the other cameras' pose it failed cameras 4, 5 and module 2).
// Such a view is set aside by its tilt, said so, in the report with its
// tilt, and in the history, and the unmoved ring reads ok.
TEST(CheckCli, AViewSeenEdgeOnIsSetAsideByItsTiltOnAnUnmovedRing) {
  const std::string dir = ::testing::TempDir() + "/check_cli_edge_on_" + std::to_string(getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  ASSERT_EQ(RunCli("simulate --out " + dir + "/ring --seed 209 --calibration-captures 8 --no-scenes --spec " +
                   std::string(STEREORIG_SOURCE_DIR) + "/datasets/specs/ring3.yaml")
                .code,
            0);
  WriteStoredRig(dir + "/ring/truth/rig.yaml", 0.022, dir + "/rig.yaml", dir + "/ring/target.yaml");
  const std::string image = dir + "/ring/calibration/005/cam5.png";
  const cv::Mat sharp = cv::imread(image, cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(sharp.empty());
  cv::Mat shifted;
  const cv::Mat image_from_sharp = (cv::Mat_<double>(2, 3) << 1, 0, -0.10, 0, 1, -0.25);
  cv::warpAffine(sharp, shifted, image_from_sharp, sharp.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  ASSERT_TRUE(cv::imwrite(image, shifted));
  const std::string report = dir + "/check.json", db = dir + "/history.sqlite";
  Result r = RunCli("check --rig " + dir + "/rig.yaml --captures " + dir + "/ring/calibration --target " + dir +
                    "/ring/target.yaml --history-db " + db + " --report " + report);
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("set aside: capture 005 cam5: board seen 83 deg from face-on (edge-on: its corners can share "
                       "one error), not used\n"),
            std::string::npos)
      << r.out;
  std::ifstream f(report);
  const nlohmann::json j = nlohmann::json::parse(f, nullptr, false);
  ASSERT_TRUE(j.is_object());
  EXPECT_EQ(j["verdict"], "ok") << j["explanation"];
  bool listed = false;
  for (const nlohmann::json& v : j["views_set_aside"]) {
    if (v["why"] != "edge_on") continue;
    EXPECT_GE(v["tilt_deg"].get<double>(), 69.5) << v.dump();
    EXPECT_EQ(v["bound_deg"], 70.0) << v.dump();
    listed |= v["capture"] == "005" && v["camera"] == 5;
  }
  EXPECT_TRUE(listed) << j["views_set_aside"].dump(2);
  r = RunCli("check --history --history-db " + db);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find(" seen edge-on (up to "), std::string::npos) << r.out;
  r = RunCli("check --history --json --history-db " + db);
  EXPECT_NE(r.out.find("\"tilt_deg\": 83."), std::string::npos) << r.out;
  fs::remove_all(dir);
}

TEST(CheckCli, AnOutputOverACaptureImageIsRefused) {
  const std::string dir = ::testing::TempDir() + "/check_cli_images";
  fs::remove_all(dir);
  fs::create_directories(dir + "/tonight/000");
  const std::string image = dir + "/tonight/000/cam2.png";
  std::ofstream(image) << "an image\n";
  const std::string head =
      "check --rig " + dir + "/rig.yaml --captures " + dir + "/tonight --target " + dir + "/target.yaml ";
  for (const std::string& outputs : {"--report " + image, "--history-db " + image}) {
    const Result r = RunCli(head + outputs);
    EXPECT_EQ(r.code, 2) << outputs;
    EXPECT_EQ(Occurrences(r.err, "stereorig check: "), 1) << r.err;
    EXPECT_NE(LastLine(r.err).find(image + ": is a capture image (--captures)"), std::string::npos) << r.err;
  }
  EXPECT_EQ(Bytes(image), "an image\n");
  fs::remove_all(dir);
}

// ---- The history as a line runs it (cron, a line controller): a history
// locked at the append, one provisioned empty, k_sigma kept, the same night
// checked twice, the per-run list. Three simulated nights shared by the
// cases: seed 21 unmoved, seed 22 unmoved (another night of the same rig),
// seed 21 with camera 2 turned 0.05 deg; the stored rig with 0.03 px
// residuals, as TheReportListsEveryNamedCamera... has it (the turned night
// reads recalibrate there by a factor of 2.3 or more, the unmoved ones ok).
class CheckHistoryCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = ::testing::TempDir() + "/check_cli_history_" + std::to_string(getpid());
    fs::remove_all(dir_);
    // The nights are rendered once for every case (MadeOnce) and copied in:
    // each case writes beside them.
    const std::string nights = testing::MadeOnce("check_cli_history_nights", [](const std::string& dir) {
      for (const auto& [name, args] : std::vector<std::pair<std::string, std::string>>{
               {"night1", "--seed 21"},
               {"night2", "--seed 22"},
               {"turned", "--seed 21 --bump-camera 2 --bump-rotation-deg 0.05"}}) {
        const Result r = RunCli("simulate --out " + dir + "/" + name + " --calibration-captures 8 --no-scenes " + args);
        ASSERT_EQ(r.code, 0) << r.err;
      }
    });
    fs::copy(nights, dir_, fs::copy_options::recursive);
    WriteStoredRig(dir_ + "/night1/truth/rig.yaml", 0.03, dir_ + "/rig.yaml", dir_ + "/night1/target.yaml");
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  // `check` of the night `captures` (a folder under dir_) into `db`.
  static Result Check(const std::string& captures, const std::string& db, const std::string& more = "") {
    return RunCli("check --rig " + dir_ + "/rig.yaml --captures " + dir_ + "/" + captures + " --target " + dir_ +
                  "/night1/target.yaml --history-db " + db + " " + more);
  }
  static nlohmann::json Report(const std::string& path) {
    std::ifstream f(path);
    return nlohmann::json::parse(f, nullptr, false);
  }
  // The report's "history" (what became of the run), an empty object where
  // there is none (a report of a version before it, or no report).
  static nlohmann::json HistoryOf(const std::string& report_path) {
    const nlohmann::json j = Report(report_path);
    return j.is_object() && j.contains("history") ? j["history"] : nlohmann::json::object();
  }
  // One value an SQL query reads from `db` ("" where none, "NULL" for null).
  static std::string Query(const std::string& db, const std::string& sql) {
    sqlite3* raw = nullptr;
    std::string v;
    sqlite3_stmt* st = nullptr;
    if (sqlite3_open_v2(db.c_str(), &raw, SQLITE_OPEN_READONLY, nullptr) == SQLITE_OK &&
        sqlite3_prepare_v2(raw, sql.c_str(), -1, &st, nullptr) == SQLITE_OK && sqlite3_step(st) == SQLITE_ROW)
      v = sqlite3_column_type(st, 0) == SQLITE_NULL ? "NULL"
                                                    : reinterpret_cast<const char*>(sqlite3_column_text(st, 0));
    sqlite3_finalize(st);
    sqlite3_close(raw);
    return v;
  }
  static int Runs(const std::string& db) {
    const std::string n = Query(db, "SELECT COUNT(*) FROM stereorig_check_runs");
    return n.empty() ? -1 : std::stoi(n);
  }
  static std::string dir_;
};
std::string CheckHistoryCli::dir_;

// Another process holds the history's write lock at the moment of the
// append (after the check's up-front writability test passed): the night's
// verdict stands. Before, a turned night printed "verdict: recalibrate",
// then exited 2 ("database is locked") with no report: the night lost. Now:
// exit 1, the report written and saying why the run is not in the history,
// a warning on stderr; and, not appended, the same captures checked again
// are no repeat: they add the night. The lock is taken once the check says
// it is detecting (its up-front test is done by then) and held until the
// check exits, past its 5 s wait for a lock.
TEST_F(CheckHistoryCli, AHistoryLockedAtTheAppendKeepsTheVerdictAndTheReport) {
  const std::string db = dir_ + "/locked.sqlite", report = dir_ + "/locked.json";
  ASSERT_EQ(Check("night1", db).code, 0);  // the history made, one run
  const std::string out = dir_ + "/locked.out", err = dir_ + "/locked.err";
  fs::remove(err);
  int status = -1;
  std::thread check([&] {
    status = std::system((kBin + " check --rig " + dir_ + "/rig.yaml --captures " + dir_ + "/turned --target " + dir_ +
                          "/night1/target.yaml --history-db " + db + " --report " + report + " >" + out + " 2>" + err)
                             .c_str());
  });
  sqlite3* other = nullptr;
  ASSERT_EQ(sqlite3_open(db.c_str(), &other), SQLITE_OK);
  bool locked = false;
  for (int tries = 0; tries < 1200 && !locked; ++tries) {  // up to a minute
    if (Bytes(err).find("check: detecting the target") != std::string::npos)
      locked = sqlite3_exec(other, "BEGIN EXCLUSIVE;", nullptr, nullptr, nullptr) == SQLITE_OK;
    else
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  check.join();
  sqlite3_exec(other, "ROLLBACK;", nullptr, nullptr, nullptr);
  sqlite3_close(other);
  ASSERT_TRUE(locked) << Bytes(err);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1) << Bytes(out) << Bytes(err);  // the verdict's: recalibrate
  EXPECT_NE(Bytes(out).find("verdict: recalibrate"), std::string::npos) << Bytes(out);
  EXPECT_NE(Bytes(out).find("history: not appended to " + db + ": it could not be written"), std::string::npos)
      << Bytes(out);
  EXPECT_NE(LastLine(Bytes(err)).find("stereorig check: warning: tonight's run is not in the history " + db),
            std::string::npos)
      << Bytes(err);
  EXPECT_NE(LastLine(Bytes(err)).find("database is locked"), std::string::npos) << Bytes(err);
  const nlohmann::json j = Report(report);
  ASSERT_TRUE(j.is_object()) << "no report";
  EXPECT_EQ(j["verdict"], "recalibrate");
  nlohmann::json history = HistoryOf(report);
  EXPECT_EQ(history["appended"], false) << history;
  EXPECT_TRUE(history.contains("run_id") && history["run_id"].is_null()) << history;
  EXPECT_NE(history.value("not_appended_why", std::string()).find("database is locked"), std::string::npos) << history;
  EXPECT_EQ(Runs(db), 1);
  EXPECT_EQ(Query(db, "PRAGMA integrity_check"), "ok");
  // Checked again, free: appended, as run 2.
  const Result again = Check("turned", db, "--report " + report);
  EXPECT_EQ(again.code, 1) << again.err;
  EXPECT_NE(again.out.find("history: appended to " + db + " (run 2)"), std::string::npos) << again.out;
  EXPECT_EQ(HistoryOf(report)["appended"], true);
  EXPECT_EQ(HistoryOf(report)["run_id"], 2);
  EXPECT_EQ(Runs(db), 2);
}

// A history file created empty (`install -m 664 /dev/null FILE`, to give a
// service user the file) is an empty database to SQLite: the first night
// makes it ours. Before, every night exited 2 ("no such table:
// stereorig_check_runs"), and `check --history` too. Another program's
// SQLite database is still refused, before any work, and left as it was.
TEST_F(CheckHistoryCli, AnEmptyHistoryFileIsMadeOursAndAnotherDatabaseRefused) {
  const std::string db = dir_ + "/provisioned.sqlite";
  { std::ofstream(db, std::ios::binary); }
  ASSERT_EQ(fs::file_size(db), 0u);
  Result r = RunCli("check --history --history-db " + db);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out, "0 runs: " + db + " holds none yet (each check appends one)\n");
  EXPECT_EQ(fs::file_size(db), 0u);  // reading it wrote nothing
  r = Check("night1", db, "--report " + dir_ + "/provisioned.json");
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_EQ(Runs(db), 1);
  EXPECT_EQ(HistoryOf(dir_ + "/provisioned.json")["run_id"], 1);
  r = RunCli("check --history --history-db " + db);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("1 run(s), ", 0), 0u) << r.out;

  const std::string foreign = dir_ + "/foreign.sqlite";
  sqlite3* raw = nullptr;
  ASSERT_EQ(sqlite3_open(foreign.c_str(), &raw), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(raw, "CREATE TABLE parts (id INTEGER);", nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(raw);
  const std::string before = Bytes(foreign);
  for (const Result& refused : {Check("night1", foreign), RunCli("check --history --history-db " + foreign)}) {
    EXPECT_EQ(refused.code, 2) << refused.out << refused.err;
    EXPECT_EQ(LastLine(refused.err), "stereorig check: " + foreign +
                                         ": an SQLite database, but not a stereorig check history (it has no table "
                                         "stereorig_check_runs): give another with --history-db");
    EXPECT_EQ(refused.err.find("detecting"), std::string::npos) << "refused only after the work: " << refused.err;
  }
  EXPECT_EQ(Bytes(foreign), before);
}

// --k-sigma sets every threshold: the report says which (key k_sigma), the
// history keeps it (stereorig_check_run_inputs.k_sigma), and `check
// --history` says when its runs were not all at one k, and each run's k
// (in its per-run list and in --history --json).
// Before, neither kept it: a night at k 0.5 sat in the trend among nights at
// 3.5, its fails counted with theirs.
TEST_F(CheckHistoryCli, KSigmaIsInTheReportTheHistoryAndItsListing) {
  const std::string db = dir_ + "/k.sqlite", report = dir_ + "/k.json";
  Result r = Check("night1", db, "--report " + report);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(Report(report).value("k_sigma", 0.0), 3.5);
  r = Check("night2", db, "--report " + report + " --k-sigma 5");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(Report(report).value("k_sigma", 0.0), 5.0);
  EXPECT_EQ(Query(db,
                  "SELECT group_concat(k_sigma, ' ') FROM (SELECT k_sigma FROM stereorig_check_run_inputs ORDER "
                  "BY run_id)"),
            "3.5 5.0");
  r = RunCli("check --history --history-db " + db);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("k_sigma varied over these runs (each run's thresholds and fails are at its own k): 3.5 in "
                       "run(s) 1; 5 in run(s) 2\n"),
            std::string::npos)
      << r.out;
  // The per-run list: run 2's row, at k 5.
  EXPECT_NE(
      r.out.find("\n     2  " + Report(report)["date_utc"].get<std::string>() + "        5  ok               0  "),
      std::string::npos)
      << r.out;
  // --history --json: every run, its k, inputs and figures, for a line
  // controller; --json alone is refused (a check's JSON is its --report).
  r = RunCli("check --history --json --history-db " + db);
  EXPECT_EQ(r.code, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out, nullptr, false);
  ASSERT_TRUE(j.is_object()) << r.out;
  ASSERT_EQ(j["runs"].size(), 2u) << r.out;
  EXPECT_EQ(j["runs"][0]["k_sigma"], 3.5);
  EXPECT_EQ(j["runs"][1]["k_sigma"], 5.0);
  EXPECT_EQ(j["runs"][1]["id"], 2);
  EXPECT_EQ(j["runs"][1]["captures_crc32"], Report(report)["captures_crc32"]);
  EXPECT_EQ(j["runs"][1]["figures"].size(), Report(report)["figures"].size()) << r.out;
  EXPECT_EQ(j["runs"][1]["figures"]["cam0_consistency_rms_px"]["pass"], true) << r.out;
  EXPECT_EQ(j["runs"][1]["views_set_aside"], nlohmann::json::array()) << r.out;
  r = RunCli("check --json --history-db " + db);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(LastLine(r.err),
            "stereorig check: --json: applies only with --history (a check's own JSON is its --report)");
}

// The same night checked again (the same captures, by a CRC-32 of their
// images, with the same rig file) is not appended again: it would count
// twice in every trend and every "fails". Before, three checks of one night
// made three runs ("fails 3"). The verdict, its exit code and the report
// are as on the first check; the report and a warning name the run it
// repeats. A copy of the night in another folder is the same night; another
// night is appended.
TEST_F(CheckHistoryCli, TheSameNightCheckedAgainIsNotAppendedTwice) {
  const std::string db = dir_ + "/twice.sqlite", report = dir_ + "/twice.json";
  Result r = Check("turned", db, "--report " + report);
  ASSERT_EQ(r.code, 1) << r.err;
  const std::string crc = Report(report).value("captures_crc32", std::string());
  EXPECT_EQ(crc.size(), 8u);
  EXPECT_EQ(Query(db, "SELECT captures_crc32 FROM stereorig_check_run_inputs"), crc);
  fs::copy(dir_ + "/turned/calibration", dir_ + "/turned_copy", fs::copy_options::recursive);
  for (const std::string& captures : {std::string("turned"), std::string("turned_copy")}) {
    fs::remove(report);
    r = Check(captures, db, "--report " + report);
    EXPECT_EQ(r.code, 1) << captures << ": " << r.err;
    EXPECT_NE(r.out.find("verdict: recalibrate"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("history: not appended to " + db + ": the same night as run 1 ("), std::string::npos) << r.out;
    EXPECT_NE(LastLine(r.err).find("stereorig check: warning: tonight's run is not in the history " + db +
                                   ": the same night as run 1 ("),
              std::string::npos)
        << r.err;
    const nlohmann::json j = Report(report);
    ASSERT_TRUE(j.is_object()) << captures << ": no report";
    EXPECT_EQ(j["captures_crc32"], crc) << captures;
    EXPECT_EQ(HistoryOf(report)["appended"], false);
    EXPECT_EQ(HistoryOf(report)["same_night_as_run"], 1);
    EXPECT_EQ(Runs(db), 1) << captures;
  }
  r = Check("night1", db);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("history: appended to " + db + " (run 2)"), std::string::npos) << r.out;
  EXPECT_EQ(Runs(db), 2);
  r = RunCli("check --history --history-db " + db);
  EXPECT_NE(r.out.find("runs:\n"), std::string::npos) << r.out;
  EXPECT_EQ(Occurrences(r.out, "  recalibrate  "), 1) << r.out;  // run 1's row, once
}

}  // namespace
}  // namespace stereorig

// ---- A corrupt history (a robustness walkthrough): a figure's value 'abc'
// read as 0.0000, a threshold of 1e308 printed as 309 digits, a NULL name a
// nameless figure; `check --history` exited 0 and a night was appended to
// it. Now every row is checked as it is read: a bad one refuses with exit 2
// naming the file, the table, the row and what is wrong, for --history,
// --history --json, and a night (before its work, the history left as it
// was); numbers are printed bounded; a new history's tables refuse such a
// row themselves.
namespace stereorig {
namespace {

// A history as a version before the CHECKs made it (its tables as they were
// created then), with `rows`.
bool MakeUncheckedHistory(const std::string& path, const std::string& rows) {
  sqlite3* raw = nullptr;
  const bool opened = sqlite3_open(path.c_str(), &raw) == SQLITE_OK;
  const std::string sql =
      "CREATE TABLE stereorig_check_runs (id INTEGER PRIMARY KEY AUTOINCREMENT, date_utc TEXT NOT NULL, rig_file TEXT "
      "NOT NULL, captures TEXT NOT NULL, verdict TEXT NOT NULL, explanation TEXT NOT NULL);"
      "CREATE TABLE stereorig_check_figures (run_id INTEGER NOT NULL REFERENCES stereorig_check_runs(id), name TEXT "
      "NOT NULL, value REAL NOT NULL, threshold REAL NOT NULL, pass INTEGER NOT NULL, samples INTEGER NOT NULL);"
      "INSERT INTO stereorig_check_runs (date_utc, rig_file, captures, verdict, explanation) VALUES "
      "('2026-11-01T02:00:00Z', '/r.yaml', '/n1', 'ok', 'every figure within its threshold');" +
      rows;
  const bool made = opened && sqlite3_exec(raw, sql.c_str(), nullptr, nullptr, nullptr) == SQLITE_OK;
  sqlite3_close(raw);
  return made;
}

TEST_F(CheckHistoryCli, ABadRowInTheHistoryIsRefusedBeforeTheNight) {
  const std::string db = dir_ + "/bad_row.sqlite", report = dir_ + "/bad_row.json";
  ASSERT_TRUE(MakeUncheckedHistory(
      db,
      "INSERT INTO stereorig_check_figures VALUES (1, 'cam0_consistency_rms_px', 0.02, 0.03, 1, 500),"
      "(1, 'pair_0_1_closure_mm', 'abc', 0.01, 1, 8);"));
  const std::string bytes = Bytes(db);
  const std::string refusal = "stereorig check: " + db +
                              ": a bad row in the history: stereorig_check_figures row 2 (run 1): the value of figure "
                              "pair_0_1_closure_mm is 'abc', not a number (mend or delete the row with sqlite3, or "
                              "give another history with --history-db)";
  for (const std::string json : {"", " --json"}) {
    const Result r = RunCli("check --history" + json + " --history-db " + db);
    EXPECT_EQ(r.code, 2) << json << ": " << r.out;
    EXPECT_EQ(r.out, "") << json;
    EXPECT_EQ(LastLine(r.err), refusal) << json;
  }
  const Result r = Check("night1", db, "--report " + report);
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_EQ(LastLine(r.err), refusal);
  EXPECT_EQ(r.err.find("check: detecting the target"), std::string::npos) << r.err;  // before the night's work
  EXPECT_FALSE(fs::exists(report));
  EXPECT_EQ(Bytes(db), bytes);
}

// A finite but huge threshold (1e308) is printed as %.4g: the table keeps
// its columns.
TEST_F(CheckHistoryCli, AHugeNumberInTheHistoryKeepsItsTableInShape) {
  const std::string db = dir_ + "/huge.sqlite";
  ASSERT_TRUE(MakeUncheckedHistory(
      db, "INSERT INTO stereorig_check_figures VALUES (1, 'cam0_consistency_rms_px', 0.02, 1e308, 1, 500);"));
  const Result r = RunCli("check --history --history-db " + db);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("     0.0200     0.0200     0.0200     0.0200     1e+308      0\n"), std::string::npos) << r.out;
  std::istringstream lines(r.out);
  for (std::string line; std::getline(lines, line);) EXPECT_LT(line.size(), 160u) << line;
}

// A history the check makes refuses a bad row itself (CHECK constraints),
// whoever writes it.
TEST_F(CheckHistoryCli, ANewHistoryRefusesABadRowItself) {
  const std::string db = dir_ + "/checked.sqlite";
  ASSERT_EQ(Check("night1", db).code, 0);
  sqlite3* raw = nullptr;
  ASSERT_EQ(sqlite3_open(db.c_str(), &raw), SQLITE_OK);
  for (const char* sql :
       {"UPDATE stereorig_check_figures SET value = 'abc';", "UPDATE stereorig_check_runs SET verdict = 'banana';"})
    EXPECT_EQ(sqlite3_exec(raw, sql, nullptr, nullptr, nullptr), SQLITE_CONSTRAINT) << sql;
  sqlite3_close(raw);
  EXPECT_EQ(RunCli("check --history --history-db " + db).code, 0);
}

// Images mixed up between cameras or captures, on an unmoved rig (a user's
// walkthrough). cam0's and cam1's images exchanged in every capture read
// "camera 0 changed: neither a new pose nor a new lens alone explains",
// camera 1 not named, exit 1: refused now, exit 2, naming the swap, with no
// report and no history. One capture whose module-0 images are another
// capture's (a trigger or sync slip) read "module 0 and module 1 disagree"
// (8.04 mm against 0.0153 mm), no capture named: set aside whole and named,
// the night ok; said once for the capture (it printed each of its four views
// as "off the capture's other views", as if each had slipped alone). The
// slip in a capture of three views, where the view test set aside the lone
// camera of the other module, goes whole too, said as either. Both readings are hundreds of px (another board pose)
// against bounds of tens of times ~0.03 px, so neither outcome hangs on the
// simulated noise.
TEST(CheckCli, ImagesSwappedBetweenCamerasOrAModuleFromAnotherCaptureAreNamed) {
  const std::string dir = ::testing::TempDir() + "/check_cli_swap_" + std::to_string(getpid());
  const std::vector<std::string> names = UnmovedNight(dir);
  ASSERT_GE(names.size(), 8u);
  Result r;
  const std::string db = dir + "/history.sqlite";
  auto check = [&](const std::string& captures, const std::string& report) {
    return RunCli("check --rig " + dir + "/rig.yaml --captures " + captures + " --target " + dir +
                  "/ds/target.yaml --history-db " + db + " --report " + report);
  };
  const std::string swapped = dir + "/swapped";
  fs::copy(dir + "/ds/calibration", swapped, fs::copy_options::recursive);
  for (const std::string& name : names) {
    const std::string at = swapped + "/" + name + "/";
    fs::rename(at + "cam0.png", at + "t.png");
    fs::rename(at + "cam1.png", at + "cam0.png");
    fs::rename(at + "t.png", at + "cam1.png");
  }
  r = check(swapped, dir + "/swapped.json");
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_EQ(Occurrences(r.err, "stereorig check: "), 1) << r.err;
  EXPECT_NE(LastLine(r.err).find(swapped + ": cam0 and cam1 look swapped: each matches the other's calibration"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir + "/swapped.json"));
  EXPECT_FALSE(fs::exists(db));

  // Captures 3 and 4 show the board to all four cameras (seed 21).
  const std::string slipped = dir + "/slipped", report = dir + "/slipped.json";
  fs::copy(dir + "/ds/calibration", slipped, fs::copy_options::recursive);
  for (const char* image : {"cam0.png", "cam1.png"})
    fs::copy_file(slipped + "/" + names[4] + "/" + image, slipped + "/" + names[3] + "/" + image,
                  fs::copy_options::overwrite_existing);
  r = check(slipped, report);
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  // Said once, for the whole capture, with why: each view "off the
  // capture's other views" read as four slips of their own.
  EXPECT_EQ(Occurrences(r.out, "set aside: "), 1) << r.out;
  EXPECT_NE(r.out.find("set aside: capture " + names[3] + " whole (cam0, cam1, cam2, cam3): its modules disagree by "),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("in this capture only: one module's images taken at another moment than the other's"),
            std::string::npos)
      << r.out;
  std::ifstream f(report);
  const nlohmann::json j = nlohmann::json::parse(f, nullptr, false);
  ASSERT_TRUE(j.is_object());
  ASSERT_EQ(j["views_set_aside"].size(), 4u) << j.dump(2);
  for (const nlohmann::json& v : j["views_set_aside"]) {
    EXPECT_EQ(v["capture"], names[3]);
    EXPECT_EQ(v["why"], "other_moment");
    EXPECT_EQ(v["whole_capture"], "modules_disagree") << j.dump(2);
  }
  EXPECT_EQ(j["verdict"], "ok") << j.dump(2);

  // The same slip in capture 2, whose cam3 sees too few corners (seed 21):
  // three views, module 0's two agreeing with each other against cam2. cam2
  // alone was set aside, named as the image taken at another moment; which
  // it was the capture cannot tell, and it says so, the capture set aside
  // whole.
  const std::string three = dir + "/three";
  fs::copy(dir + "/ds/calibration", three, fs::copy_options::recursive);
  for (const char* image : {"cam0.png", "cam1.png"})
    fs::copy_file(three + "/" + names[4] + "/" + image, three + "/" + names[2] + "/" + image,
                  fs::copy_options::overwrite_existing);
  r = check(three, dir + "/three.json");
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_EQ(Occurrences(r.out, "set aside: "), 1) << r.out;
  EXPECT_NE(
      r.out.find("set aside: capture " + names[2] + " whole (cam0, cam1, cam2): cam2 is off module 0's views by "),
      std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("cam2's image or module 0's taken at another moment than the other, which the capture cannot "
                       "tell"),
            std::string::npos)
      << r.out;

  // The same slip in capture 3, whose cam3's image is noisy (grey levels
  // with a standard deviation of 25): cam3 goes first, its corners jumping
  // about their own pose, and then the three views left go whole. The whole
  // capture went unsaid: its whole-capture line was printed only where the
  // entry before it was another capture's, and cam3's came first. The jump
  // reads ~0.5 px against a bound of ~0.075 px (2.5 times ~0.03 px), the
  // slip hundreds of px against tens of times ~0.03 px.
  const std::string jumped = dir + "/jumped";
  fs::copy(dir + "/ds/calibration", jumped, fs::copy_options::recursive);
  for (const char* image : {"cam0.png", "cam1.png"})
    fs::copy_file(jumped + "/" + names[4] + "/" + image, jumped + "/" + names[3] + "/" + image,
                  fs::copy_options::overwrite_existing);
  {
    const std::string path = jumped + "/" + names[3] + "/cam3.png";
    cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE), noise(image.size(), CV_16SC1);
    cv::RNG rng(1);
    rng.fill(noise, cv::RNG::NORMAL, 0, 25);
    cv::Mat noisy;
    cv::add(image, noise, noisy, cv::noArray(), CV_8UC1);  // saturating
    cv::imwrite(path, noisy);
  }
  r = check(jumped, dir + "/jumped.json");
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_EQ(Occurrences(r.out, "set aside: "), 2) << r.out;
  EXPECT_NE(r.out.find("set aside: capture " + names[3] + " cam3: its corners jump about their own board pose by "),
            std::string::npos)
      << r.out;
  EXPECT_NE(
      r.out.find("set aside: capture " + names[3] + " whole (cam0, cam1, cam2): cam2 is off module 0's views by "),
      std::string::npos)
      << r.out;
  fs::remove_all(dir);
}

// A board printed 0.3 % large (the simulator's scale_error_ppm: each face's
// print scaled about its first corner, the plate as the file says) against
// its nominal file, the rig unmoved. Every module measures it +0.30 %, but
// the board scaled as a solid leaves its back face 0.27 mm off where the
// print puts it (the faces' first corners 90 mm apart), and the night read
// cameras 0 and 3 "neither" (the walkthrough's seed 701). With the faces'
// prints scaled alone every figure holds: said as the board's print, no
// camera named, and the target file refused (the rig's scale, which the
// board as a solid explains, is still said so, exit 1:
// EveryLensDriftedAlikeOrTheRigsScale...). The 0.3 % is 15
// times the 0.02 % the modules' size reading scatters by (board_scale.h);
// the message holds the fitted size to 0.300-0.309 %, within a tenth of
// it (the unit test holds shared_scale alike).
TEST(CheckCli, ABoardPrintedOffItsFileIsSaidAsThePrintNotAsTwoCameras) {
  const std::string dir = ::testing::TempDir() + "/check_cli_print_" + std::to_string(getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  ASSERT_EQ(RunCli("simulate --write-default-spec " + dir + "/default.yaml").code, 0);
  std::string spec = Bytes(dir + "/default.yaml");
  const size_t at = spec.find("scale_error_ppm: 0");
  ASSERT_NE(at, std::string::npos) << spec;
  spec.replace(at, std::string("scale_error_ppm: 0").size(), "scale_error_ppm: 3000");
  std::ofstream(dir + "/print.yaml") << spec;
  Result r = RunCli("simulate --spec " + dir + "/print.yaml --out " + dir +
                    "/ds --seed 701 --calibration-captures 8 --no-scenes");
  ASSERT_EQ(r.code, 0) << r.err;
  WriteStoredRig(dir + "/ds/truth/rig.yaml", 0.03, dir + "/rig.yaml", dir + "/ds/target.yaml");
  // Neither ok nor recalibrate: the rig agrees with itself, its scale
  // cannot be checked against a board of unknown size, and recalibrated
  // against this file every baseline and S would take the print's 0.3 %
  // (the night read every module flagged and "recalibrate", exit 1). The
  // target file refused (exit 2), no report, no night in the history.
  const Result c = RunCli("check --rig " + dir + "/rig.yaml --captures " + dir + "/ds/calibration --target " + dir +
                          "/ds/target.yaml --history-db " + dir + "/history.sqlite --report " + dir + "/print.json");
  EXPECT_EQ(c.code, 2) << c.out << c.err;
  EXPECT_NE(c.err.find(dir + "/ds/target.yaml: the board's print is not its file's size: every module measures the "
                             "board 0.30"),
            std::string::npos)
      << c.err;
  EXPECT_NE(c.err.find("no camera or module changed, the rig's scale unchecked (measure the board; recalibrated "
                       "against this file, every baseline and S would take the print's error)"),
            std::string::npos)
      << c.err;
  EXPECT_EQ(c.err.find("neither"), std::string::npos) << c.err;
  EXPECT_EQ(c.out.find("verdict:"), std::string::npos) << c.out;
  EXPECT_FALSE(fs::exists(dir + "/print.json"));
  EXPECT_FALSE(fs::exists(dir + "/history.sqlite"));
  fs::remove_all(dir);
}

// A module shifted 0.1 or 0.3 mm, on the walkthrough's seed 505, whose
// nights have captures of three views: the lone camera, read through the
// other module's views alone, carries the whole shift, while its bound came
// from its four-view captures where its partner's pose absorbs it, and the
// capture was set aside as taken at another moment (the walkthrough's
// calibrated rig, 0.1 mm: capture 001, 0.621 px against a bound of 0.608
// px; the truth rig here, 0.3 mm: capture 005). Compared like for like,
// nothing is set aside and the closure still fails. A trigger slip in a
// capture of three views is still set aside
// (NightlyCheck.ASlipInACaptureOfThreeViewsIsNotBlamedOnTheLoneModulesCamera).
TEST(CheckCli, AModuleShiftSetsNoCaptureOfThreeViewsAsideAsTakenAtAnotherMoment) {
  const std::string dir = ::testing::TempDir() + "/check_cli_shift3_" + std::to_string(getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  // The rig as stored: the truth of a night before the shift (a bumped
  // night's truth is the bumped rig).
  ASSERT_EQ(RunCli("simulate --out " + dir + "/unmoved --seed 505 --calibration-captures 1 --no-scenes").code, 0);
  WriteStoredRig(dir + "/unmoved/truth/rig.yaml", 0.03, dir + "/rig.yaml", dir + "/unmoved/target.yaml");
  for (const std::string mm : {"0.1", "0.3"}) {
    const std::string captures = dir + "/shifted" + mm;
    Result r = RunCli("simulate --out " + captures + " --seed 505 --calibration-captures 8 --no-scenes " +
                      "--bump-module 1 --bump-translation-mm " + mm);
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string report = dir + "/shifted" + mm + ".json";
    r = RunCli("check --rig " + dir + "/rig.yaml --captures " + captures + "/calibration --target " + captures +
               "/target.yaml --history-db " + dir + "/history.sqlite --report " + report);
    EXPECT_EQ(r.code, 1) << r.out << r.err;
    EXPECT_EQ(r.out.find("set aside"), std::string::npos) << mm << " mm: " << r.out;
    std::ifstream f(report);
    const nlohmann::json j = nlohmann::json::parse(f, nullptr, false);
    ASSERT_TRUE(j.is_object());
    EXPECT_EQ(j["views_set_aside"], nlohmann::json::array()) << mm << " mm: " << j["views_set_aside"].dump(2);
    EXPECT_EQ(j["flagged_modules"], nlohmann::json::array({0, 1})) << mm << " mm: " << j["explanation"];
  }
  fs::remove_all(dir);
}

// An unmoved night one of whose captures is noisier than the rest: seed 502
// (8 captures), whose capture 006 module 0 sees nearly edge-on, both views
// at 0.035 px about their own poses against the night's 0.024 px. Its cam0
// view, read through cam1's 28-corner one-camera pose, was judged with the
// night's sigma, which understated that pose's error, and failed module 0's
// stereo figure (the demo's calibrated rig: 0.0485 px against 0.0439, "module
// 0's cameras disagree"; this truth rig at the demo's calibration RMS, 0.0215
// px: 0.0484 against 0.0422). With each view's own noise the skip rule sets
// that view aside (the pose predicts it worse than its noise) and the figure
// passes (0.0266 against 0.0360), and camera 0's principal point moved 0.05
// px on the same night, the smallest drift the study catches (its camera 1
// +0.05 px, docs/verify-and-check.md), is still flagged and named (cam0
// 0.0464 px against 0.0300).
TEST(CheckCli, ACaptureNoisierThanTheRestOfAnUnmovedNightIsNoAlarmAndADriftThereStillIs) {
  const std::string dir = ::testing::TempDir() + "/check_cli_noisy_capture_" + std::to_string(getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  ASSERT_EQ(RunCli("simulate --out " + dir + "/unmoved --seed 502 --calibration-captures 8 --no-scenes").code, 0);
  WriteStoredRig(dir + "/unmoved/truth/rig.yaml", 0.0215, dir + "/rig.yaml", dir + "/unmoved/target.yaml");
  Result r = RunCli("check --rig " + dir + "/rig.yaml --captures " + dir + "/unmoved/calibration --target " + dir +
                    "/unmoved/target.yaml --history-db " + dir + "/history.sqlite");
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("verdict: ok"), std::string::npos) << r.out;
  ASSERT_EQ(RunCli("simulate --out " + dir + "/drifted --seed 502 --calibration-captures 8 --no-scenes " +
                   "--bump-camera 0 --bump-principal-point-px 0.05 0")
                .code,
            0);
  const std::string report = dir + "/drifted.json";
  r = RunCli("check --rig " + dir + "/rig.yaml --captures " + dir + "/drifted/calibration --target " + dir +
             "/unmoved/target.yaml --history-db " + dir + "/history.sqlite --report " + report);
  EXPECT_EQ(r.code, 1) << r.out << r.err;
  std::ifstream f(report);
  const nlohmann::json j = nlohmann::json::parse(f, nullptr, false);
  ASSERT_TRUE(j.is_object());
  EXPECT_EQ(j["flagged_cameras"], nlohmann::json::array({0})) << j["explanation"];
  fs::remove_all(dir);
}

// --k-sigma's help and its refusal said "k times its figure's sigma", but
// a threshold is the figure's expected value on an unchanged rig plus k
// standard deviations (a mean square's expectation is not zero), and the
// calibration's own projection uncertainty at k (the consistency figures'
// (k u_px)^2): they say both now.
TEST(CheckCli, KSigmaIsSaidAsStandardDeviationsAboveTheExpectedValue) {
  const Result help = RunCli("check --help");
  EXPECT_EQ(help.code, 0) << help.err;
  EXPECT_NE(help.out.find("expected value on an unchanged rig plus k of its standard deviations"), std::string::npos)
      << help.out;
  EXPECT_NE(help.out.find("and the calibration's own projection uncertainty at k"), std::string::npos) << help.out;
  EXPECT_EQ(help.out.find("k times"), std::string::npos) << help.out;
  const std::string dir = ::testing::TempDir() + "/check_cli_ksigma_" + std::to_string(getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  const Result refused =
      RunCli("check --rig " + dir + "/rig.yaml --captures " + dir + " --target " + dir + "/target.yaml --k-sigma 11");
  EXPECT_EQ(refused.code, 2) << refused.out << refused.err;
  EXPECT_NE(refused.err.find("--k-sigma: must be in (0, 10] (each threshold is its figure's expected value on an "
                             "unchanged rig plus k of its standard deviations, and the calibration's own "
                             "projection uncertainty at k)"),
            std::string::npos)
      << refused.err;
  fs::remove_all(dir);
}

// A night copied with one capture's images renamed Cam0.png ... and another
// capture's folder renamed .005: check skipped both without a word and
// judged "6 captures, 24 views, verdict: ok", two of the 8 captures lost.
// A folder holding images none named camK.png is refused (exit 2, naming
// it and its files); a hidden folder is still skipped, but named on stdout
// and in the report's "skipped_folders".
TEST(CheckCli, AMisnamedCaptureIsRefusedAndAHiddenOneNamed) {
  const std::string dir = ::testing::TempDir() + "/check_cli_skipped_" + std::to_string(getpid());
  const std::vector<std::string> names = UnmovedNight(dir);
  ASSERT_GE(names.size(), 8u);
  const std::string captures = dir + "/night", report = dir + "/night.json";
  fs::copy(dir + "/ds/calibration", captures, fs::copy_options::recursive);
  const std::string misnamed = captures + "/" + names[3];
  for (int c = 0; c < 4; ++c)
    fs::rename(misnamed + "/cam" + std::to_string(c) + ".png", misnamed + "/Cam" + std::to_string(c) + ".png");
  const std::string hidden = captures + "/." + names[5];
  fs::rename(captures + "/" + names[5], hidden);
  const std::string args =
      " --target " + dir + "/ds/target.yaml --history-db " + dir + "/history.sqlite --report " + report;
  Result r = RunCli("check --rig " + dir + "/rig.yaml --captures " + captures + args);
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find(misnamed + ": holds Cam0.png, Cam1.png, Cam2.png, Cam3.png but no camK.png"), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(report));
  // Its images moved a folder deeper: refused as well.
  fs::create_directories(misnamed + "/images");
  for (int c = 0; c < 4; ++c)
    fs::rename(misnamed + "/Cam" + std::to_string(c) + ".png", misnamed + "/images/cam" + std::to_string(c) + ".png");
  r = RunCli("check --rig " + dir + "/rig.yaml --captures " + captures + args);
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find(misnamed + ": holds images/cam0.png, "), std::string::npos) << r.err;
  // Named right, the hidden one is skipped and said.
  for (int c = 0; c < 4; ++c)
    fs::rename(misnamed + "/images/cam" + std::to_string(c) + ".png", misnamed + "/cam" + std::to_string(c) + ".png");
  fs::remove(misnamed + "/images");
  r = RunCli("check --rig " + dir + "/rig.yaml --captures " + captures + args);
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("skipped " + hidden + ": not a capture"), std::string::npos) << r.out;
  std::ifstream f(report);
  const nlohmann::json j = nlohmann::json::parse(f, nullptr, false);
  ASSERT_TRUE(j.is_object());
  EXPECT_EQ(j["skipped_folders"], nlohmann::json::array({hidden})) << j.dump(2);
  fs::remove_all(dir);
}

// --- False alarms of unmoved nights (fix-check-fa) ---

// Seed 1016, nothing moved: in capture 003 module 1's cam2 sees 31 corners
// (the board partly out of view), cam3 all 99, and cam3 read through cam2's
// pose held 90 % of module 1's stereo figure's variance. That pose errs by
// tonight's noise and by the calibration's error, which add in the pose; the
// check summed each's own sum of squares, leaving out their cross term, and
// gave the view 0.59 times its variance: 0.0537 px against 0.0501, "module
// 1's cameras disagree" (1 of 100 unmoved default nights). With the
// variance of the summed pose error, 0.0537 against 0.0538 (this truth rig
// at the demo's RMS): the night is a tail event of its own pose error
// (cam2's pose off the truth by chi-square 17.3 on 6 degrees of freedom,
// p ~ 0.008), passed but not by much. The test reads the figure and its
// threshold from the report and asks that the night passes by under 5 %
// (0.998 of the threshold when written): the "ok" is this margin's, and a
// night that passed by far would no longer test the weak pose. And
// camera 1 turned 0.01 deg on the same night, the smallest turn the audit
// tried, is named alone (it named camera 2 too, "turned 0.001 deg").
TEST(CheckCli, AnUnmovedNightsViewThroughAWeakPoseIsNoAlarmAndASmallTurnIsNamedAlone) {
  const std::string dir = ::testing::TempDir() + "/check_cli_weak_pose_" + std::to_string(getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  ASSERT_EQ(RunCli("simulate --out " + dir + "/unmoved --seed 1016 --calibration-captures 8 --no-scenes").code, 0);
  WriteStoredRig(dir + "/unmoved/truth/rig.yaml", 0.0215, dir + "/rig.yaml", dir + "/unmoved/target.yaml");
  const std::string args = " --target " + dir + "/unmoved/target.yaml --history-db " + dir + "/history.sqlite";
  Result r = RunCli("check --rig " + dir + "/rig.yaml --captures " + dir + "/unmoved/calibration" + args +
                    " --report " + dir + "/unmoved.json");
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("verdict: ok"), std::string::npos) << r.out;
  {
    std::ifstream unmoved(dir + "/unmoved.json");
    const nlohmann::json u = nlohmann::json::parse(unmoved, nullptr, false);
    ASSERT_TRUE(u.is_object());
    double ratio = NAN;
    for (const nlohmann::json& fig : u["figures"])
      if (fig["name"] == "module1_stereo_consistency_rms_px")
        ratio = fig["value"].get<double>() / fig["threshold"].get<double>();
    EXPECT_TRUE(ratio > 0.95 && ratio <= 1)
        << "module 1's stereo figure is " << ratio
        << " of its threshold: this test is of a night that passes by a hair (0.998 when written)\n"
        << u["figures"].dump(2);
  }
  ASSERT_EQ(RunCli("simulate --out " + dir + "/turned --seed 1016 --calibration-captures 8 --no-scenes " +
                   "--bump-camera 1 --bump-rotation-deg 0.01")
                .code,
            0);
  const std::string report = dir + "/turned.json";
  r = RunCli("check --rig " + dir + "/rig.yaml --captures " + dir + "/turned/calibration" + args + " --report " +
             report);
  EXPECT_EQ(r.code, 1) << r.out << r.err;
  std::ifstream f(report);
  const nlohmann::json j = nlohmann::json::parse(f, nullptr, false);
  ASSERT_TRUE(j.is_object());
  EXPECT_EQ(j["flagged_cameras"], nlohmann::json::array({1})) << j["explanation"];
  fs::remove_all(dir);
}

// ---- Nights that must not read a plain ok (fix-check-ok) ----

// The report `path` as JSON (discarded, not an object, when unreadable).
nlohmann::json ReadReport(const std::string& path) {
  std::ifstream f(path);
  return nlohmann::json::parse(f, nullptr, false);
}

// A camera knocked during the night's last capture reads as that capture's
// image of another moment: set aside, the rest of the night within every
// threshold, and the night read "ok", exit 0 (camera 2 turned 3 deg in the
// last of 8 captures: 12.952 px off against a bound of 0.293 px in the
// audit that asked for this test; not measured here). No later
// view of the camera tells a knock (it stays) from a slip (it does not): the
// night reads recapture, exit 1, naming the capture and the camera. Here the
// last capture's cam2.png is another capture's (off by hundreds of px, as
// the knock, far over its bound): the night cannot tell it from a knock.
// A night far noisier than the calibration (its thresholds rise with the
// noise until a change passes under them: the audit that asked for this
// test read module 1 shifted 0.05 mm ok at 20 times; not measured here)
// reads recapture too, with a warning saying what the
// thresholds still see. The stored rig claims a calibration RMS a sixth of
// the smallest noise the unmoved night reads on any camera, so every camera
// reads 6 times its calibration's or more, over kNoisyNightFactor (5); the
// same night against the rig stored at 0.03 px (the night's own noise, about
// 1 time) reads ok with no warning.
TEST(CheckCli, AViewSetAsideInItsLastCaptureOrANightFarNoisierThanItsCalibrationReadsRecapture) {
  const std::string dir = ::testing::TempDir() + "/check_cli_recapture_" + std::to_string(getpid());
  const std::vector<std::string> names = UnmovedNight(dir);
  ASSERT_GE(names.size(), 8u);
  const std::string target = " --target " + dir + "/ds/target.yaml --history-db " + dir + "/history.sqlite";
  Result r = RunCli("check --rig " + dir + "/rig.yaml --captures " + dir + "/ds/calibration" + target + " --report " +
                    dir + "/unmoved.json");
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("verdict: ok (every figure within its threshold)"), std::string::npos) << r.out;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  const nlohmann::json unmoved = ReadReport(dir + "/unmoved.json");
  ASSERT_TRUE(unmoved.is_object());
  EXPECT_TRUE(unmoved.contains("noise_warning") && unmoved["noise_warning"].is_null()) << unmoved.dump(2);
  EXPECT_EQ(unmoved["corner_noise"].size(), 4u) << unmoved.dump(2);
  double quietest_px = 0.03;  // where the report says nothing, the rig's
  for (const nlohmann::json& n : unmoved.value("corner_noise", nlohmann::json::array())) {
    EXPECT_EQ(n["calibration_px"], 0.03);
    quietest_px = std::min(quietest_px, n["tonight_px"].get<double>());
  }

  // The last capture's cam2 from another capture.
  const std::string knocked = dir + "/knocked";
  fs::copy(dir + "/ds/calibration", knocked, fs::copy_options::recursive);
  fs::copy_file(knocked + "/" + names[3] + "/cam2.png", knocked + "/" + names.back() + "/cam2.png",
                fs::copy_options::overwrite_existing);
  r = RunCli("check --rig " + dir + "/rig.yaml --captures " + knocked + target + " --report " + dir + "/knocked.json");
  EXPECT_EQ(r.code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("verdict: recapture (capture " + names.back() + ": cam2 by "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" px) off its capture's other views and no later capture shows cam2"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("and no later capture shows cam2: knocked during that capture (it stays so) or an image "
                       "taken at another moment (it does not), which the night cannot tell: capture again before "
                       "production (every figure within its threshold))"),
            std::string::npos)
      << r.out;
  const nlohmann::json k = ReadReport(dir + "/knocked.json");
  ASSERT_TRUE(k.is_object());
  EXPECT_EQ(k["verdict"], "recapture");
  ASSERT_EQ(k["views_set_aside"].size(), 1u) << k.dump(2);
  EXPECT_EQ(k["views_set_aside"][0]["camera"], 2);
  EXPECT_EQ(k["views_set_aside"][0]["left_open"], true) << k.dump(2);
  // The history keeps the verdict (a history from before it refused it).
  r = RunCli("check --history --history-db " + dir + "/history.sqlite");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find(" recapture "), std::string::npos) << r.out;

  // The same night against a calibration 6 times quieter than tonight.
  WriteStoredRig(dir + "/ds/truth/rig.yaml", quietest_px / 6, dir + "/quiet_rig.yaml", dir + "/ds/target.yaml");
  r = RunCli("check --rig " + dir + "/quiet_rig.yaml --captures " + dir + "/ds/calibration" + target + " --report " +
             dir + "/noisy.json");
  EXPECT_EQ(r.code, 1) << r.out << r.err;
  EXPECT_NE(r.err.find("stereorig check: warning: tonight's corner noise is many times the calibration's (cam0 "),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("a change below them goes unseen tonight (pair_0_1_closure_mm "), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("verdict: recapture (tonight's corner noise is many times the calibration's"), std::string::npos)
      << r.out;
  const nlohmann::json noisy = ReadReport(dir + "/noisy.json");
  ASSERT_TRUE(noisy.is_object());
  EXPECT_EQ(noisy["verdict"], "recapture");
  EXPECT_TRUE(noisy["noise_warning"].is_string()) << noisy.dump(2);
  fs::remove_all(dir);
}

// Refusals that named the wrong cause, and a lost image that cost the night.
// A module's cables swapped with the other's (cam0<->cam2, cam1<->cam3) read
// "captures of another rig, or the wrong rig file or target file?", though
// under that exchange every figure is within its threshold: named now. An
// extra cam4.png read "camera 4, but the rig has 4 cameras": the cameras are
// numbered from 0, said so. A rig file whose every baseline (and S) is 1.5
// times the captures' rig's (a 60 mm rig's night against a 90 mm rig file)
// blamed the board's squares alone: the baselines are named too. One capture
// missing cam2.png refused the night (exit 2) while an empty capture folder is
// skipped: the capture is set aside whole with a warning naming the file,
// the night judged on the other 7 (ok, exit 0).
TEST(CheckCli, ExchangedCablesABaselineOffAndAnExtraCameraAreNamedAndAMissingImageCostsOneCapture) {
  const std::string dir = ::testing::TempDir() + "/check_cli_causes_" + std::to_string(getpid());
  const std::vector<std::string> names = UnmovedNight(dir);
  ASSERT_GE(names.size(), 8u);
  const std::string target = " --target " + dir + "/ds/target.yaml --history-db " + dir + "/history.sqlite";
  auto copy = [&](const std::string& name) {
    fs::copy(dir + "/ds/calibration", dir + "/" + name, fs::copy_options::recursive);
    return dir + "/" + name;
  };

  const std::string swapped = copy("swapped");
  for (const std::string& n : names)
    for (const auto& [a, b] : {std::pair{0, 2}, std::pair{1, 3}}) {
      const std::string ca = swapped + "/" + n + "/cam" + std::to_string(a) + ".png";
      const std::string cb = swapped + "/" + n + "/cam" + std::to_string(b) + ".png";
      fs::rename(ca, ca + ".tmp"), fs::rename(cb, ca), fs::rename(ca + ".tmp", cb);
    }
  Result r = RunCli("check --rig " + dir + "/rig.yaml --captures " + swapped + target);
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("but with the cameras' images exchanged (cam0.png is cam2's, cam1.png is cam3's, cam2.png is "
                       "cam0's, cam3.png is cam1's) every figure is within its threshold: cables or image folders "
                       "mixed up? (the faces of the board seen: cam0 "),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("captures of another rig"), std::string::npos) << r.err;

  const std::string extra = copy("extra");
  fs::copy_file(extra + "/" + names[2] + "/cam0.png", extra + "/" + names[2] + "/cam4.png");
  r = RunCli("check --rig " + dir + "/rig.yaml --captures " + extra + target);
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("cam4.png: camera 4, but the rig has 4 cameras, cam0.png to cam3.png (numbered from 0)"),
            std::string::npos)
      << r.err;

  RigChange wider;
  wider.scale = 1 / 1.5;  // the rig file's baselines 1.5 times the night's
  WriteChangedRig(dir + "/rig.yaml", dir + "/wide_rig.yaml", wider);
  r = RunCli("check --rig " + dir + "/wide_rig.yaml --captures " + dir + "/ds/calibration" + target);
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("; or the captures' rig has every baseline 0.667 times the rig file's"), std::string::npos)
      << r.err;

  const std::string missing = copy("missing");
  fs::remove(missing + "/" + names[3] + "/cam2.png");
  // An empty image (a failed write leaves 0 bytes) costs its capture too:
  // it refused the night ("is empty (0 bytes: still being written?)").
  // One line a capture.
  std::ofstream(missing + "/" + names[4] + "/cam0.png", std::ios::trunc).close();
  fs::remove(missing + "/" + names[4] + "/cam1.png");
  std::ofstream(missing + "/" + names[5] + "/cam3.png", std::ios::trunc).close();
  r = RunCli("check --rig " + dir + "/rig.yaml --captures " + missing + target + " --report " + dir + "/missing.json");
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("set aside: capture " + names[3] + " whole: cam2.png missing; not used"), std::string::npos)
      << r.out;
  EXPECT_NE(r.err.find("stereorig check: warning: " + missing + "/" + names[3] +
                       "/cam2.png: missing; its capture set aside, the night judged without it"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.out.find("set aside: capture " + names[4] +
                       " whole: cam0.png empty (0 bytes), cam1.png missing; not "
                       "used"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.err.find("stereorig check: warning: " + missing + "/" + names[4] +
                       "/cam0.png: empty (0 bytes); its capture set aside"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.out.find("set aside: capture " + names[5] + " whole: cam3.png empty (0 bytes); not used"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("verdict: ok"), std::string::npos) << r.out;
  const nlohmann::json j = ReadReport(dir + "/missing.json");
  ASSERT_TRUE(j.is_object());
  EXPECT_EQ(j["missing_images"],
            nlohmann::json::array({missing + "/" + names[3] + "/cam2.png", missing + "/" + names[4] + "/cam0.png",
                                   missing + "/" + names[4] + "/cam1.png", missing + "/" + names[5] + "/cam3.png"}))
      << j.dump(2);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace stereorig
