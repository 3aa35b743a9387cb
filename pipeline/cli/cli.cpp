#include "pipeline/cli/cli.h"

#include "core/log.h"
#include "pipeline/cli/commands.h"

#include <iostream>
#include <sstream>

namespace hp {

std::string CommandLine::value(const std::string& option, const std::string& fallback) const {
    auto it = values.find(option);
    return it == values.end() || it->second.empty() ? fallback : it->second.back();
}

namespace {

const std::vector<OptionSpec>& sceneOptionSpecs() {
    static const std::vector<OptionSpec> specs = {
        {"--frames", "RANGE", "frames to produce: 5, 1-120, 1-120x2, 3,7,10-20 (default: the scene's)"},
        {"--set", "KEY=VALUE", "override a scene key, typed and validated like the file (repeatable)"},
        {"--out", "DIR", "output folder (default: the scene's output.directory, else out/<scene>)"},
        {"--threads", "N", "worker threads (default: all cores)"},
        {"--seed", "N", "random seed (overrides the scene's seed)"},
        {"--force", "", "rewrite outputs that already exist (default: skip them and resume)"},
    };
    return specs;
}

const std::vector<OptionSpec>& commonOptionSpecs() {
    static const std::vector<OptionSpec> specs = {
        {"-q", "", "quiet: only warnings and errors"},
        {"-v", "", "verbose"},
        {"--help", "", "show this help"},
    };
    return specs;
}

const OptionSpec* findOption(const CommandSpec& cmd, const std::string& name) {
    for (const auto* list : {&cmd.options, &commonOptionSpecs()})
        for (const OptionSpec& o : *list)
            if (o.name == name) return &o;
    if (cmd.sceneOptions)
        for (const OptionSpec& o : sceneOptionSpecs())
            if (o.name == name) return &o;
    return nullptr;
}

const CommandSpec* findCommand(const std::string& name) {
    for (const CommandSpec& c : commands())
        if (c.name == name) return &c;
    return nullptr;
}

void appendOptions(std::ostringstream& out, const std::vector<OptionSpec>& options) {
    for (const OptionSpec& o : options) {
        std::string left = "  " + o.name + (o.argument.empty() ? "" : " " + o.argument);
        if (left.size() < 24) left.resize(24, ' ');
        else left += "  ";
        out << left << o.help << "\n";
    }
}

}  // namespace

std::string generalHelp() {
    std::ostringstream out;
    out << "hairpipe — grow, simulate and render hair on an animated head\n\n"
           "usage: hairpipe <command> [options] scene.yaml\n\ncommands:\n";
    for (const CommandSpec& c : commands()) {
        std::string name = "  " + c.name;
        name.resize(14, ' ');
        out << name << c.summary << "\n";
    }
    out << "\n'hairpipe <command> --help' describes a command's options.\n"
           "Exit codes: 0 success, 1 usage or scene error, 2 some frame failed.\n";
    return out.str();
}

std::string commandHelp(const CommandSpec& c) {
    std::ostringstream out;
    out << "usage: hairpipe " << c.name << " " << c.usage << "\n\n" << c.summary << "\n";
    if (!c.details.empty()) out << "\n" << c.details << "\n";
    out << "\noptions:\n";
    appendOptions(out, c.options);
    if (c.sceneOptions) appendOptions(out, sceneOptionSpecs());
    appendOptions(out, commonOptionSpecs());
    return out.str();
}

CommandLine parseCommandLine(const std::vector<std::string>& args) {
    CommandLine cl;
    if (args.empty()) throw UsageError("no command given\n\n" + generalHelp());
    cl.command = args[0];
    if (cl.command == "--help" || cl.command == "-h") {
        cl.command = "help";
        return cl;
    }
    const CommandSpec* cmd = findCommand(cl.command);
    if (!cmd) throw UsageError("unknown command '" + cl.command + "'\n\n" + generalHelp());
    for (size_t i = 1; i < args.size(); ++i) {
        std::string arg = args[i];
        if (arg == "--") {
            cl.positional.insert(cl.positional.end(), args.begin() + i + 1, args.end());
            break;
        }
        if (arg.size() < 2 || arg[0] != '-' || (arg[1] >= '0' && arg[1] <= '9')) {
            cl.positional.push_back(arg);
            continue;
        }
        std::string inlineValue;
        bool hasInline = false;
        const size_t eq = arg.find('=');
        if (arg.compare(0, 2, "--") == 0 && eq != std::string::npos) {
            inlineValue = arg.substr(eq + 1);
            arg = arg.substr(0, eq);
            hasInline = true;
        }
        if (arg == "-h") arg = "--help";
        const OptionSpec* opt = findOption(*cmd, arg);
        if (!opt) throw UsageError("hairpipe " + cl.command + ": unknown option '" + arg + "' (see --help)");
        if (opt->argument.empty()) {
            if (hasInline) throw UsageError("option " + arg + " takes no value");
            cl.values[arg].push_back("");
        } else if (hasInline) {
            cl.values[arg].push_back(inlineValue);
        } else {
            if (i + 1 >= args.size()) throw UsageError("option " + arg + " needs a value " + opt->argument);
            cl.values[arg].push_back(args[++i]);
        }
    }
    return cl;
}

int runCli(const std::vector<std::string>& args) {
    const CommandLine cl = parseCommandLine(args);
    if (cl.has("-q")) setLogLevel(LogLevel::Quiet);
    if (cl.has("-v")) setLogLevel(LogLevel::Verbose);
    const CommandSpec* cmd = findCommand(cl.command);
    if (cl.has("--help") || !cmd) {
        if (!cmd) {
            std::cout << generalHelp();
            return kExitOk;
        }
        std::cout << commandHelp(*cmd);
        return kExitOk;
    }
    return cmd->run(cl);
}

}  // namespace hp
