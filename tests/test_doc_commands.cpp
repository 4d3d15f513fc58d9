// Every command line of README.md and docs/*.md that runs one of the apps is parsed with that app's own
// declarations and checked with its own flag checks (everything the app checks before it reads a file):
// a flag renamed, dropped or given other values breaks the documentation, and this test says which line.
// The commands are taken from the code blocks (a line that runs tilesplat-render, -bench, -info or
// -viewer, with its '\' continuations) and from inline code in the prose that runs a built app
// (`./build/apps/tilesplat-...`; a span such as `tilesplat-render --png` names a flag, not a command).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "bench_options.h"
#include "cli.h"
#include "info_options.h"
#include "render_options.h"
#include "viewer_options.h"

namespace {

namespace fs = std::filesystem;
namespace cli = tilesplat::cli;

struct DocCommand {
  std::string where;    // "README.md:212"
  std::string program;  // "tilesplat-render"
  std::vector<std::string> args;
  std::string text;  // as written, for messages
};

// Splits a command as a POSIX shell would for these lines: words separated by blanks, with '...'
// and "..." quoting.
std::vector<std::string> shell_words(const std::string& text) {
  std::vector<std::string> words;
  std::string word;
  bool in_word = false;
  char quote = 0;
  for (const char c : text) {
    if (quote) {
      if (c == quote)
        quote = 0;
      else
        word += c;
    } else if (c == '\'' || c == '"') {
      quote = c;
      in_word = true;
    } else if (c == ' ' || c == '\t') {
      if (in_word) words.push_back(word);
      word.clear();
      in_word = false;
    } else {
      word += c;
      in_word = true;
    }
  }
  if (in_word) words.push_back(word);
  return words;
}

// "tilesplat-render a.ply -o x.exr  # comment && more" -> the command up to a comment or a next command.
std::string command_part(std::string text) {
  for (const char* end : {" #", " && ", " | ", " > ", " 2>"}) {
    const auto at = text.find(end);
    if (at != std::string::npos) text.resize(at);
  }
  return text;
}

const std::regex& app_command() {
  static const std::regex pattern(
      R"((?:^|[\s`])(?:\./)?(?:build/apps/)?(tilesplat-(?:render|bench|info|viewer))(\s.*|$))");
  return pattern;
}

void add_command(std::vector<DocCommand>& commands, const std::string& where, const std::string& text) {
  std::smatch match;
  if (!std::regex_search(text, match, app_command())) return;
  const std::string rest = command_part(match[2].str());
  // "tilesplat-bench ... --sort radix": an elided example, not a command.
  if (rest.find("...") != std::string::npos && rest.find("...") == rest.find_first_not_of(' ')) return;
  if (rest.find(" ... ") != std::string::npos) return;
  DocCommand command{where, match[1].str(), shell_words(rest), command_part(match[0].str())};
  // A program named in the prose without arguments (`tilesplat-bench`) is not a command.
  if (command.args.empty()) return;
  commands.push_back(std::move(command));
}

std::vector<DocCommand> doc_commands(const fs::path& file, const std::string& name) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  std::vector<DocCommand> commands;
  bool in_code = false;
  std::string paragraph;
  size_t paragraph_line = 0;
  auto flush_paragraph = [&] {
    // Inline code spans of the prose, which may break across lines.
    for (size_t open = paragraph.find('`'); open != std::string::npos;) {
      const size_t close = paragraph.find('`', open + 1);
      if (close == std::string::npos) break;
      // Only a span that runs a built app is a command; `tilesplat-render --png` names a flag.
      const std::string span = paragraph.substr(open + 1, close - open - 1);
      if (span.find("build/apps/tilesplat-") != std::string::npos)
        add_command(commands, name + ":" + std::to_string(paragraph_line), span);
      open = paragraph.find('`', close + 1);
    }
    paragraph.clear();
  };
  for (size_t i = 0; i < lines.size(); ++i) {
    const std::string& line = lines[i];
    if (line.rfind("```", 0) == 0) {
      flush_paragraph();
      in_code = !in_code;
      continue;
    }
    if (in_code) {
      std::string joined = line;
      const size_t first = i;
      while (!joined.empty() && joined.back() == '\\' && i + 1 < lines.size()) {
        joined.pop_back();
        joined += ' ' + lines[++i];
      }
      add_command(commands, name + ":" + std::to_string(first + 1), joined);
      continue;
    }
    if (line.empty()) {
      flush_paragraph();
      continue;
    }
    if (paragraph.empty()) paragraph_line = i + 1;
    paragraph += (paragraph.empty() ? "" : " ") + line;
  }
  flush_paragraph();
  return commands;
}

std::vector<DocCommand> all_doc_commands() {
  const fs::path root = TILESPLAT_SOURCE_DIR;
  std::vector<DocCommand> commands = doc_commands(root / "README.md", "README.md");
  for (const auto& entry : fs::recursive_directory_iterator(root / "docs")) {
    if (entry.path().extension() != ".md") continue;
    auto more = doc_commands(entry.path(), fs::relative(entry.path(), root).string());
    commands.insert(commands.end(), more.begin(), more.end());
  }
  return commands;
}

// Parses the command as its app does and runs the app's checks of the flags; throws what they throw.
void parse_as_the_app_does(const DocCommand& command) {
  std::vector<std::string> words = {command.program};
  words.insert(words.end(), command.args.begin(), command.args.end());
  std::vector<const char*> argv;
  for (const auto& word : words) argv.push_back(word.c_str());
  const int argc = int(argv.size());
  if (command.program == "tilesplat-render") {
    namespace app = tilesplat::render_app;
    app::RenderOptions options;
    cli::ArgParser parser(app::kProgram, app::kUsage, app::kDescription);
    app::add_render_options(parser, options);
    if (parser.parse(argc, argv.data()) != cli::ArgParser::Outcome::kRun || options.common.list_devices)
      return;
    if (!parser.seen("--merge-manifests")) app::check_render_flags(parser, options);
  } else if (command.program == "tilesplat-bench") {
    namespace app = tilesplat::bench;
    app::BenchOptions options;
    cli::ArgParser parser(app::kProgram, app::kUsage, app::kDescription);
    app::add_bench_options(parser, options);
    if (parser.parse(argc, argv.data()) != cli::ArgParser::Outcome::kRun || options.common.list_devices)
      return;
    app::check_bench_flags(parser, options);
  } else if (command.program == "tilesplat-info") {
    namespace app = tilesplat::info;
    app::InfoOptions options;
    cli::ArgParser parser(app::kProgram, app::kUsage, app::kDescription);
    app::add_info_options(parser, options);
    if (parser.parse(argc, argv.data()) != cli::ArgParser::Outcome::kRun) return;
    app::check_info_flags(options);
  } else if (command.program == "tilesplat-viewer") {
    namespace app = tilesplat::viewer;
    app::ViewerOptions options;
    cli::ArgParser parser(app::kProgram, app::kUsage, app::kDescription);
    app::add_viewer_options(parser, options);
    if (parser.parse(argc, argv.data()) != cli::ArgParser::Outcome::kRun || options.common.list_devices)
      return;
    app::check_viewer_flags(parser, options);
  } else {
    throw std::runtime_error("no app called " + command.program);
  }
}

// The error parse_as_the_app_does throws, or "" when it accepts the command.
std::string parse_error(const DocCommand& command) {
  try {
    parse_as_the_app_does(command);
    return {};
  } catch (const std::exception& error) {
    return error.what();
  }
}

bool uses_plugin(const DocCommand& command) {
  for (const auto& arg : command.args)
    if (arg == "--sort-plugin") return true;
  return false;
}

// A command that loads a sort plugin (--sort-plugin) is parsed in a child process, which loads the
// in-tree build of the example plugin first, as the app does: its strategies then stay out of this
// process's registry. Returns the child's error message, or "".
std::string parse_error_with_plugin(DocCommand command) {
  for (size_t i = 0; i + 1 < command.args.size(); ++i)
    if (command.args[i] == "--sort-plugin") command.args[i + 1] = TILESPLAT_SORT_PLUGIN;
  int pipe_fds[2];
  if (pipe(pipe_fds) != 0) return "pipe failed";
  const pid_t child = fork();
  if (child == 0) {
    close(pipe_fds[0]);
    std::string error;
    try {
      std::vector<std::string> words = {command.program};
      words.insert(words.end(), command.args.begin(), command.args.end());
      std::vector<const char*> argv;
      for (const auto& word : words) argv.push_back(word.c_str());
      cli::load_sort_plugins(int(argv.size()), argv.data());
      error = parse_error(command);
    } catch (const std::exception& e) {
      error = e.what();
    }
    const ssize_t written = write(pipe_fds[1], error.data(), error.size());
    _exit(written == ssize_t(error.size()) ? 0 : 1);
  }
  close(pipe_fds[1]);
  std::string error;
  char buffer[512];
  for (ssize_t n; (n = read(pipe_fds[0], buffer, sizeof buffer)) > 0;) error.append(buffer, size_t(n));
  close(pipe_fds[0]);
  int status = 0;
  waitpid(child, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return "the child process failed: " + error;
  return error;
}

TEST(DocCommands, EveryDocumentedCommandParsesAsItsAppParsesIt) {
  const std::vector<DocCommand> commands = all_doc_commands();
  std::map<std::string, int> per_program;
  for (const auto& command : commands) {
    ++per_program[command.program];
    const std::string error = uses_plugin(command) ? parse_error_with_plugin(command) : parse_error(command);
    EXPECT_EQ(error, "") << command.where << ": " << command.text;
  }
  // The extraction finds the commands at all: the README alone shows each app several times.
  EXPECT_GE(per_program["tilesplat-render"], 15);
  EXPECT_GE(per_program["tilesplat-bench"], 15);
  EXPECT_GE(per_program["tilesplat-info"], 2);
  EXPECT_GE(per_program["tilesplat-viewer"], 3);
  std::printf("[ measure  ] %zu documented commands: %d render, %d bench, %d info, %d viewer\n",
              commands.size(), per_program["tilesplat-render"], per_program["tilesplat-bench"],
              per_program["tilesplat-info"], per_program["tilesplat-viewer"]);
}

// The check above can fail: a documented command with a flag the app does not have, or a value it
// refuses, or flags it does not combine, is reported with the app's own message.
TEST(DocCommands, AMistakeInADocumentedCommandIsCaught) {
  const std::vector<DocCommand> commands = all_doc_commands();
  ASSERT_FALSE(commands.empty());
  for (const char* program : {"tilesplat-render", "tilesplat-bench", "tilesplat-info", "tilesplat-viewer"}) {
    const auto command = std::find_if(commands.begin(), commands.end(), [&](const DocCommand& c) {
      return c.program == program && !uses_plugin(c);
    });
    ASSERT_NE(command, commands.end()) << program;
    DocCommand renamed = *command;
    renamed.args.push_back("--no-such-flag");
    EXPECT_EQ(parse_error(renamed), "unknown flag '--no-such-flag' (see --help)") << command->text;
  }
  EXPECT_EQ(parse_error({"x", "tilesplat-render", {"a.ply", "-o", "a.exr", "--width", "0"}, ""}),
            "--width expects a positive integer, got '0'");
  EXPECT_EQ(parse_error({"x", "tilesplat-render", {"a.ply", "-o", "a.png"}, ""}),
            "-o expects an .exr file, got 'a.png' (use --png for a PNG preview)");
  EXPECT_EQ(parse_error({"x", "tilesplat-bench", {"--sort-bench", "a.ply"}, ""}),
            "--sort-bench sorts random keys and takes no SCENE");
  EXPECT_EQ(parse_error({"x", "tilesplat-bench", {"--effects", "a.ply", "--plot", "a.svg"}, ""}),
            "--plot does not apply to --effects");
  EXPECT_EQ(parse_error({"x", "tilesplat-viewer", {"a.ply", "--screenshot", "a.jpg"}, ""}),
            "--screenshot expects an .exr or .png file, got 'a.jpg'");
  EXPECT_EQ(parse_error({"x", "tilesplat-info", {"--json"}, ""}), "missing the FILE argument (see --help)");
}

TEST(DocCommands, ShellWordsFollowQuotes) {
  EXPECT_EQ(shell_words("a.ply -o 'out dir/x.exr' --sort \"radix\""),
            (std::vector<std::string>{"a.ply", "-o", "out dir/x.exr", "--sort", "radix"}));
  EXPECT_EQ(command_part("a.ply -o x.exr  # a comment"), "a.ply -o x.exr ");
}

}  // namespace
