// Shared pieces of the subcommands: argument parsing with the project's exit
// codes, the scenes of a simulator dataset a command is asked for, and the
// "not built yet" answer of subcommands still to come.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "calib/core/printable_text.h"  // PrintableText, for every error line
#include "calib/core/rig.h"

namespace stereorig {

// Parses argv into `app`. Returns an exit code when the command must stop now
// (0 after printing --help to stdout; 2 after one line on stderr for a usage
// error), or std::nullopt when it should run. An option given an empty
// value ("--target ''", "--rig $UNSET") is a usage error, "--target: an
// empty value" (or NonEmptyPath's "an empty path" where the option has that
// check; an option with another check of its own, a choice or a range,
// answers with that one's message, which runs first): before, an input read as not given (target drew the built-in
// board, score scored the truth rig, rig skipped --truth) and the run
// exited 0.
std::optional<int> ParseArgs(CLI::App& app, int argc, char** argv);

// The scene names of a --scenes argument, "cup,sphere" -> {cup, sphere}.
// Throws InputError on an empty name ("cup,,sphere", "cup,"), one named
// twice, or one holding a '/' ("cup/": a path, not a scene's name).
std::vector<std::string> SplitSceneList(const std::string& list);

// Throws InputError unless every scene of `scenes` is in the simulator
// dataset `dataset`, i.e. DATASET/scenes/<name>/active is a folder
// (docs/formats.md "Datasets"). For the scenes a user named (`score`, and
// `bench` with --scenes given): a misspelt one is refused before any work,
// not skipped or found after the others were run. One missing scene is
// named by its folder; several by the dataset's scenes/ folder and a list.
void CheckScenesInDataset(const std::string& dataset, const std::vector<std::string>& scenes);

// The scenes of `dataset` a command (`score`, `bench`) runs, in the order of
// `scenes`. With `named` (the user gave --scenes): all of them, each one
// required (CheckScenesInDataset). Otherwise `scenes` is the default list:
// those of it the dataset holds (DATASET/scenes/<name>/active a folder), the
// others skipped; throws InputError naming the dataset when it holds none.
std::vector<std::string> ScenesToRun(const std::string& dataset, const std::vector<std::string>& scenes, bool named);

// Throws InputError naming `dataset` unless it is a folder, and (with
// need_truth: no --rig given, so its truth/rig.yaml is the rig) one with
// truth/ in it: a file or a wrong folder given to --dataset is named as
// such, not as a missing DATASET/truth/rig.yaml.
void CheckDatasetFolder(const std::string& dataset, bool need_truth);

// Throws InputError naming `rig_path` unless `rig`'s modules pair the same
// cameras, module by module, as the dataset's truth rig at `truth_rig_path`
// (`truth`), and are as many. `command` ("score", "bench") judges the
// cloud's module m against the truth's module m (its fill target, its left
// camera's depth): a rig of another layout (module 0 on cameras 2 and 3) was
// judged against the wrong module's truth, and its figures judged nothing.
// The message names both rig files and the first module that differs.
void RequireTruthRigLayout(const Rig& rig, const std::string& rig_path, const Rig& truth,
                           const std::string& truth_rig_path, const std::string& command);

// `word` as a POSIX shell reads it back as one word: as it is when it
// holds only letters, digits and _@%+=:,./- (most paths), else in single
// quotes, each ' written '\'' ("a b" -> 'a b', "" -> ''). For a command
// line printed to be pasted (reconstruct --rectified-out's match command):
// a path with a space split into two arguments there.
std::string ShellQuoted(const std::string& word);

// Checks of a number option with a short message ("must be positive, got
// 0"): CLI11's PositiveNumber and NonNegativeNumber name their range with
// DBL_MAX's 309 digits.
const CLI::Validator& PositiveValue();
const CLI::Validator& NonNegativeValue();
// A count option `name` into *count (its default shown as it is): a whole
// number in [1, 2^31 - 1], decimal ("must be a whole number >= 1, got 1.5";
// CLI11's own conversion said "Could not convert"). Read here, as
// AddSeedOption's seed is: CLI11 took a leading 0 as octal after a check
// that read it as decimal (010 passed as ten and ran as 8; 09 passed, then
// "Could not convert").
CLI::Option* AddCountOption(CLI::App& app, const std::string& name, int* count, const std::string& description);
// A whole-number option `name` into *value (its default shown as it is), in
// [min, max], decimal, a sign before it or none; refused by the flag's
// name, its rule and the value given ("must be a whole number in [2, 1024],
// got 1.5", "must be in [2, 1024], got 99999999999"), where CLI11 said
// "Could not convert". AddCountOption is one, in [1, 2^31 - 1].
CLI::Option* AddWholeNumberOption(CLI::App& app, const std::string& name, int* value, int min, int max,
                                  const std::string& description);
// Its check alone, for an option of several whole numbers (match --roi):
// each value is checked so, before CLI11 converts it.
CLI::Validator WholeNumberIn(int min, int max);

// A --seed option into *seed (its default shown as it is): a whole number
// from 0 to max_seed, decimal (leading zeros are zeros) or hex with 0x,
// nothing else. CLI11's own reading takes a leading 0 as octal: a script's
// zero-padded seeds (seq -w: 01 .. 20) made 010 seed 8 without a word and
// refused 08; a negative seed wrapped round to 2^64 - 1 and one above it
// was saturated. Each is refused by the flag's name (exit 2).
CLI::Option* AddSeedOption(CLI::App& app, uint64_t* seed, uint64_t max_seed, const std::string& description);

// Check of a path option (every file or folder a command writes, and
// verify's inputs): an empty one ("--report ''", a shell variable left unset)
// is refused as "an empty path". Before, it read as not given (verify wrote
// no report and exited 0) or as a file named "" ("cannot open").
const CLI::Validator& NonEmptyPath();

// Flushes stdout and throws InputError("standard output", ...) if anything
// written to it was lost (a full disk, /dev/full): a command whose result is
// its table must not exit 0 when the table was not written.
void RequireStdoutWritten();

// fflush(stdout), keeping the reason of the first flush that fails for
// StdoutWriteError (a later flush finds the stream's error flag set, not why).
// The commands flush through it after each line a caller may wait for.
void FlushStdout();

// "" if everything written to stdout so far reached it (flushed now), else
// why not ("No space left on device", "Broken pipe"; "a write failed" where
// a printf that filled the buffer failed and its reason is gone). A stream
// checks it after each capture's line (reconstruct_stream.h).
std::string StdoutWriteError();

// The process's exit code once `program` ("stereorig reconstruct") returned
// `code`: where stdout lost anything it printed (a full disk, /dev/full, a
// closed descriptor, a reader gone with SIGPIPE ignored), a run that
// returned 0 returns 2 after one line on stderr, "<program>: standard
// output: cannot be written: <why>", since the caller did not get what the
// run printed (its table, each capture's line). A check that returned 1 (it
// ran and failed: check's history and report hold the verdict) keeps its 1
// after the same line. A run that returned 2 keeps it and its own line.
// Called once, by main, for every command (and --help, --version), after
// the command has ended: files it wrote are complete and stay
// (docs/formats.md, "CLI").
int ExitCodeWithStdout(int code, const std::string& program);

// The warning, without its "<command>: warning: " (its caller prints it
// and keeps it in its report), if the folder `dir` holds .cameramodel files
// other than `written` (the paths or names --export-cameramodels just wrote
// there), else "": a 3-module rig's cam4 and cam5 stayed silently beside a
// 2-module rig's fresh cam0..cam3, a folder of models of two rigs. Hidden
// files are not counted.
std::string OtherCameramodelsNote(const std::string& dir, const std::vector<std::string>& written);

// For subcommands a later issue fills in: prints what it will do and exits 2.
int NotBuiltYet(const char* name, const char* what, int argc, char** argv);

}  // namespace stereorig
