// Running a third-party scene reader in a child process (see readInChildProcess in
// import_internal.h and the "Process isolation" note in scene_import.h).
#include "import_internal.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <new>
#include <poll.h>
#include <spawn.h>
#include <string>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <type_traits>
#include <unistd.h>
#include <utility>
#include <vector>

namespace chaintube::formats::detail {

namespace {

// --- the child's answer -----------------------------------------------------------------------
// The message pipe carries messages: one type byte, a 64-bit payload length, the payload. The
// scene itself is written into a memory file (memfd) the parent made before starting the reader
// and maps afterwards: no copying through the pipe for a scene of many megabytes. Both ends are
// built from these sources on one machine, so numbers travel in native representation; the
// reader checks kProtocol first (a reader program of another build refuses to answer).
/// Change with any change to the messages or to serialise().
constexpr const char* kProtocol = "chaintube-scene-reader-protocol-1";
constexpr char kProgress = 'P'; ///< payload: the stage fraction, a double
constexpr char kResult = 'R';   ///< payload: the answer's size in the memory file, a uint64
constexpr char kRefusal = 'E';  ///< payload: the FileError reason (the last message)
constexpr std::size_t kHeaderSize = 1 + sizeof(std::uint64_t);
constexpr std::size_t kOutputLimit = 64 * 1024; ///< of the child's stderr kept for the error

/// Writes values into `out` if given, else only counts the bytes (the first of two passes:
/// the answer's size is known before its buffer is made).
class Serialiser
{
public:
    explicit Serialiser(char* out = nullptr) : m_out(out) {}
    template <typename T> void value(const T& v)
    {
        static_assert(std::is_trivially_copyable_v<T>);
        put(&v, sizeof v);
    }
    void text(const std::string& s)
    {
        value(static_cast<std::uint64_t>(s.size()));
        put(s.data(), s.size());
    }
    template <typename T> void array(const std::vector<T>& v)
    {
        static_assert(std::is_trivially_copyable_v<T>);
        value(static_cast<std::uint64_t>(v.size()));
        put(v.data(), v.size() * sizeof(T));
    }
    std::size_t size() const { return m_size; }

private:
    void put(const void* data, std::size_t size)
    {
        if (m_out && size > 0) std::memcpy(m_out + m_size, data, size);
        m_size += size;
    }
    char* m_out;
    std::size_t m_size = 0;
};

/// Reads what Serialiser wrote; every read is bounds-checked, so a truncated or inconsistent
/// answer is an error and never a read past the buffer.
class Deserialiser
{
public:
    Deserialiser(const char* data, std::size_t size, const std::filesystem::path& file)
        : m_data(data), m_size(size), m_file(file)
    {
    }
    template <typename T> T value()
    {
        T v;
        std::memcpy(&v, take(sizeof v), sizeof v);
        return v;
    }
    std::string text()
    {
        const std::size_t size = count(1);
        return std::string(take(size), size);
    }
    template <typename T> std::vector<T> array()
    {
        const std::size_t size = count(sizeof(T));
        std::vector<T> v(size);
        if (size > 0) std::memcpy(v.data(), take(size * sizeof(T)), size * sizeof(T));
        return v;
    }
    /// An element count that the remaining bytes can hold at `elementSize` bytes each.
    std::size_t count(std::size_t elementSize)
    {
        const auto n = value<std::uint64_t>();
        if (n > (m_size - m_at) / elementSize) fail();
        return static_cast<std::size_t>(n);
    }
    bool atEnd() const { return m_at == m_size; }
    [[noreturn]] void fail() const
    {
        throw FileError(m_file, "internal error: the importer process's answer is inconsistent");
    }

private:
    const char* take(std::size_t size)
    {
        if (size > m_size - m_at) fail();
        const char* at = m_data + m_at;
        m_at += size;
        return at;
    }
    const char* m_data;
    std::size_t m_size;
    std::size_t m_at = 0;
    const std::filesystem::path& m_file;
};

void serialise(const ReaderResult& result, Serialiser& out)
{
    out.value(result.metresPerReaderUnit);
    out.value(result.sourceUnitsPerReaderUnit);
    const ImportedScene& scene = result.scene;
    out.text(scene.format);
    out.value(scene.sourceUnits.metresPerUnit);
    out.text(scene.sourceUnits.unitName);
    out.value(scene.sourceUnits.unitSource);
    out.value(scene.sourceUnits.upAxis);
    out.value(scene.sourceUnits.upAxisSource);
    out.value(static_cast<std::uint64_t>(scene.meshes.size()));
    for (const SceneMesh& mesh : scene.meshes) {
        out.text(mesh.name);
        out.array(mesh.positions);
        out.array(mesh.normals);
        out.array(mesh.indices);
    }
    out.value(static_cast<std::uint64_t>(scene.nodes.size()));
    for (const SceneNode& node : scene.nodes) {
        out.text(node.name);
        out.value(node.generatedName);
        out.text(node.path);
        out.value(node.parent);
        out.array(node.children);
        for (int k = 0; k < 16; ++k)
            out.value(node.localTransform.data()[k]);
        out.array(node.meshes);
    }
}

/// The inverse of serialise(), checking the invariants finaliseScene() relies on (parents
/// before children, indices in range, whole triangles), so that even a corrupted answer cannot
/// make the caller index out of bounds.
ReaderResult deserialise(const char* data, std::size_t size, const std::filesystem::path& file)
{
    Deserialiser in(data, size, file);
    ReaderResult result;
    result.metresPerReaderUnit = in.value<double>();
    result.sourceUnitsPerReaderUnit = in.value<double>();
    ImportedScene& scene = result.scene;
    scene.format = in.text();
    scene.sourceUnits.metresPerUnit = in.value<double>();
    scene.sourceUnits.unitName = in.text();
    scene.sourceUnits.unitSource = in.value<UnitSource>();
    scene.sourceUnits.upAxis = in.value<UpAxis>();
    scene.sourceUnits.upAxisSource = in.value<UnitSource>();
    const auto isUnitSource = [](UnitSource source) {
        return source == UnitSource::FileHeader || source == UnitSource::FormatConvention ||
               source == UnitSource::Assumed || source == UnitSource::UserOverride;
    };
    if (!isUnitSource(scene.sourceUnits.unitSource) ||
        !isUnitSource(scene.sourceUnits.upAxisSource) ||
        (scene.sourceUnits.upAxis != UpAxis::PositiveY &&
         scene.sourceUnits.upAxis != UpAxis::PositiveZ))
        in.fail();
    scene.meshes.resize(in.count(1));
    for (SceneMesh& mesh : scene.meshes) {
        mesh.name = in.text();
        mesh.positions = in.array<float>();
        mesh.normals = in.array<float>();
        mesh.indices = in.array<std::uint32_t>();
        if (mesh.positions.size() % 3 != 0 || mesh.normals.size() != mesh.positions.size() ||
            mesh.indices.size() % 3 != 0)
            in.fail();
        for (const std::uint32_t index : mesh.indices)
            if (index >= mesh.vertexCount()) in.fail();
    }
    scene.nodes.resize(in.count(1));
    for (std::size_t i = 0; i < scene.nodes.size(); ++i) {
        SceneNode& node = scene.nodes[i];
        node.name = in.text();
        node.generatedName = in.value<bool>();
        node.path = in.text();
        node.parent = in.value<int>();
        node.children = in.array<int>();
        for (int k = 0; k < 16; ++k)
            node.localTransform.data()[k] = in.value<double>();
        node.meshes = in.array<int>();
        if ((i == 0) != (node.parent < 0) || node.parent >= static_cast<int>(i)) in.fail();
        for (const int child : node.children)
            if (child <= static_cast<int>(i) || child >= static_cast<int>(scene.nodes.size()))
                in.fail();
        for (const int mesh : node.meshes)
            if (mesh < 0 || mesh >= static_cast<int>(scene.meshes.size())) in.fail();
    }
    if (!in.atEnd()) in.fail();
    return result;
}

// --- the child ----------------------------------------------------------------------------

/// Writes all of `bytes` to `fd`; false if the parent is gone.
bool writeAll(int fd, const char* bytes, std::size_t size)
{
    while (size > 0) {
        const ssize_t n = ::write(fd, bytes, size);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;
        bytes += n;
        size -= static_cast<std::size_t>(n);
    }
    return true;
}

bool sendMessage(int fd, char type, const std::string& payload)
{
    char header[kHeaderSize];
    header[0] = type;
    const auto length = static_cast<std::uint64_t>(payload.size());
    std::memcpy(header + 1, &length, sizeof length);
    return writeAll(fd, header, sizeof header) && writeAll(fd, payload.data(), payload.size());
}

constexpr int kResultFd = 3;           ///< the message pipe's write end in the child
constexpr int kSceneFd = 4;            ///< the memory file in the child
constexpr int kExitParentGone = 120;   ///< the child's exit status when the parent died first
constexpr int kExitCannotAnswer = 121; ///< … when writing the answer failed
constexpr int kExitBadArguments = 122; ///< … when started with arguments it cannot use

/// Serialises the result into the memory file; sets the answer's size, returns an error
/// message ("" if all went well).
std::string writeScene(const ReaderResult& result, std::uint64_t& size)
{
    Serialiser counter;
    serialise(result, counter);
    size = counter.size();
    if (size == 0) return {};
    // fallocate (not ftruncate): a full tmpfs or memory limit is an error here, not a SIGBUS
    // when a page is first written.
    if (::fallocate(kSceneFd, 0, 0, static_cast<off_t>(size)) != 0)
        return std::string("cannot hand over the scene (") + std::strerror(errno) + ")";
    void* mapping = ::mmap(nullptr, size, PROT_WRITE, MAP_SHARED, kSceneFd, 0);
    if (mapping == MAP_FAILED)
        return std::string("cannot hand over the scene (") + std::strerror(errno) + ")";
    Serialiser writer(static_cast<char*>(mapping));
    serialise(result, writer);
    ::munmap(mapping, size);
    return {};
}

} // namespace

/// The arguments readInChildProcess puts after the reader program's own: kProtocol, the file,
/// the parent's process id, then the options (metres per unit or "-", up axis "y", "z" or "-",
/// chordal and angular tolerance, progress "1" or "0"; numbers as hexadecimal floats, exact).
constexpr int kTailArguments = 8;

[[noreturn]] void serveAsReaderProgram(int argc, char** argv, const ReaderProgramFunction& reader)
{
    const char* program = argc > 0 ? argv[0] : "reader";
    const auto usage = [&](const std::string& problem) {
        std::fprintf(stderr,
                     "%s: %s\n%s reads a scene file for ChainTube's scene import "
                     "(formats::importScene), which starts it with its answer pipe on descriptor "
                     "3 and a memory file on 4; it is not meant to be run by hand.\n",
                     program, problem.c_str(), program);
        ::_exit(kExitBadArguments);
    };
    if (argc < 1 + kTailArguments)
        usage("expected at least " + std::to_string(kTailArguments) + " arguments, got " +
              std::to_string(std::max(argc - 1, 0)));
    if (std::string(argv[argc - kTailArguments]) != kProtocol)
        usage(std::string("this program speaks ") + kProtocol + ", its caller " +
              argv[argc - kTailArguments] + " (a reader program of another build?)");
    const int tail = argc - kTailArguments + 1;
    const auto number = [&](int at, const char* what) {
        char* end = nullptr;
        const double value = std::strtod(argv[at], &end);
        if (end == argv[at] || *end != '\0' || !std::isfinite(value))
            usage(std::string("argument ") + std::to_string(at) + " (" + what +
                  "): expected a number, got '" + argv[at] + "'");
        return value;
    };
    const std::filesystem::path file = argv[tail];
    const auto parent = static_cast<pid_t>(number(tail + 1, "the parent's process id"));
    ImportOptions options;
    if (std::string(argv[tail + 2]) != "-")
        options.metresPerUnit = number(tail + 2, "metres per unit");
    const std::string up = argv[tail + 3];
    if (up == "y")
        options.upAxis = UpAxis::PositiveY;
    else if (up == "z")
        options.upAxis = UpAxis::PositiveZ;
    else if (up != "-")
        usage("argument " + std::to_string(tail + 3) + " (up axis): expected y, z or -");
    options.chordalTolerance = number(tail + 4, "chordal tolerance");
    options.angularTolerance = number(tail + 5, "angular tolerance");
    const std::string progress = argv[tail + 6];
    if (progress != "0" && progress != "1")
        usage("argument " + std::to_string(tail + 6) + " (progress): expected 0 or 1");
    const std::vector<std::string> arguments(argv + 1, argv + tail - 1); // before kProtocol

    // Die with the caller's thread (a killed editor or a timed-out fuzzer leaves no reader
    // behind); it may have died before this line.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(kExitParentGone);
    // A crash must end this process by its signal: a sanitizer's handlers (installed before
    // main in a sanitized build) would turn it into an exit status.
    for (const int signal : {SIGABRT, SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGTRAP, SIGSYS, SIGPIPE})
        std::signal(signal, SIG_DFL);

    if (progress == "1") { // the parent decides about cancelling (it kills this process)
        options.progress = [](double fraction) {
            std::string payload(sizeof fraction, '\0');
            std::memcpy(payload.data(), &fraction, sizeof fraction);
            return sendMessage(kResultFd, kProgress, payload);
        };
    }
    bool sent = false;
    try {
        ProgressStage stage(options, file, 0.0, 1.0);
        const ReaderResult result = reader(arguments, file, options, stage);
        std::uint64_t size = 0;
        const std::string failure = writeScene(result, size);
        if (failure.empty()) {
            std::string payload(sizeof size, '\0');
            std::memcpy(payload.data(), &size, sizeof size);
            sent = sendMessage(kResultFd, kResult, payload);
        } else {
            sent = sendMessage(kResultFd, kRefusal, failure);
        }
    } catch (const FileError& error) {
        sent = sendMessage(kResultFd, kRefusal, error.reason());
    } catch (const std::bad_alloc&) {
        sent = sendMessage(kResultFd, kRefusal, "out of memory while reading the file");
    } catch (const std::exception& error) {
        sent = sendMessage(kResultFd, kRefusal, std::string("the reader failed: ") + error.what());
    } catch (...) {
        sent = sendMessage(kResultFd, kRefusal, "the reader failed with an unknown exception");
    }
    // _exit: the answer is out; nothing of this short-lived process needs tearing down.
    ::_exit(sent ? 0 : kExitCannotAnswer);
}

namespace {

// --- the parent -----------------------------------------------------------------------------

class Descriptor
{
public:
    Descriptor() = default;
    Descriptor(const Descriptor&) = delete;
    Descriptor& operator=(const Descriptor&) = delete;
    ~Descriptor() { reset(); }
    int get() const { return m_fd; }
    void reset(int fd = -1)
    {
        if (m_fd >= 0) ::close(m_fd);
        m_fd = fd;
    }

private:
    int m_fd = -1;
};

/// The child until it has been waited for; on any early exit of the parent's loop (Cancelled,
/// an exception from the caller's callback) it is killed and reaped.
class ChildProcess
{
public:
    explicit ChildProcess(pid_t pid) : m_pid(pid) {}
    ChildProcess(const ChildProcess&) = delete;
    ChildProcess& operator=(const ChildProcess&) = delete;
    ~ChildProcess()
    {
        if (m_pid <= 0) return;
        ::kill(m_pid, SIGKILL);
        waitStatus();
    }
    /// Waits for the child to end; its wait status, or −1 if it cannot be had (someone else
    /// reaped it, e.g. with SIGCHLD ignored).
    int waitStatus()
    {
        int status = 0;
        pid_t waited;
        do {
            waited = ::waitpid(m_pid, &status, 0);
        } while (waited < 0 && errno == EINTR);
        m_pid = -1;
        return waited < 0 ? -1 : status;
    }

private:
    pid_t m_pid;
};

std::string signalName(int signal)
{
    const char* abbreviation = ::sigabbrev_np(signal);
    const char* description = ::strsignal(signal);
    std::string name = "signal " + std::to_string(signal);
    if (abbreviation) name += std::string(", SIG") + abbreviation;
    if (description) name += std::string(": ") + description;
    return name;
}

/// The last non-empty line of the child's output, at most 300 characters.
std::string lastLine(const std::string& output)
{
    std::size_t end = output.find_last_not_of(" \t\r\n");
    if (end == std::string::npos) return {};
    const std::size_t begin = output.rfind('\n', end);
    std::string line = output.substr(begin == std::string::npos ? 0 : begin + 1,
                                     end + 1 - (begin == std::string::npos ? 0 : begin + 1));
    if (line.size() > 300) line = line.substr(0, 297) + "...";
    return line;
}

/// Reads what is available on `fd` onto the end of `into`, keeping at most `limit` bytes
/// there (the rest is read and dropped); false at end of file.
bool readAvailable(int fd, std::string& into, std::size_t limit, const std::filesystem::path& file)
{
    char chunk[16 * 1024];
    ssize_t n;
    do {
        n = ::read(fd, chunk, sizeof chunk);
    } while (n < 0 && errno == EINTR);
    if (n < 0)
        throw FileError(file, std::string("cannot read from the importer process: ") +
                                  std::strerror(errno));
    into.append(chunk, std::min(static_cast<std::size_t>(n), limit - std::min(limit, into.size())));
    return n > 0;
}

} // namespace

std::filesystem::path readerProgram(const std::string& name, const std::filesystem::path& file)
{
    namespace fs = std::filesystem;
    if (const char* chosen = std::getenv("CHAINTUBE_READERS_DIR"); chosen && *chosen) {
        const fs::path program = fs::path(chosen) / name;
        if (::access(program.c_str(), X_OK) != 0)
            throw FileError(file, "cannot start the importer process: CHAINTUBE_READERS_DIR is '" +
                                      std::string(chosen) + "', which holds no executable " + name);
        return program;
    }
    std::error_code ignored;
    const fs::path beside = fs::read_symlink("/proc/self/exe", ignored).parent_path() / name;
    if (!ignored && ::access(beside.c_str(), X_OK) == 0) return beside;
    const fs::path built = fs::path(CHAINTUBE_READERS_BUILT_IN) / name;
    if (::access(built.c_str(), X_OK) == 0) return built;
    throw FileError(file, "cannot start the importer process: " + name +
                              " not found (looked beside this program, in " +
                              beside.parent_path().string() + ", and where it was built, " +
                              built.parent_path().string() +
                              "; set CHAINTUBE_READERS_DIR to the folder that holds it)");
}

ReaderResult readInChildProcess(const std::filesystem::path& file, const std::string& readerName,
                                const ImportOptions& options, ProgressStage& progress,
                                const ReaderProgram& program)
{
    const auto cannotStart = [&](const char* what) {
        return FileError(file, "cannot start the importer process (" + std::string(what) +
                                   "): " + std::strerror(errno));
    };
    // Every descriptor is close-on-exec; the child gets copies at fixed numbers (below). The
    // parent's copies are moved above 10 first, so that no source number is also a target.
    const auto above10 = [&](Descriptor& descriptor) {
        const int moved = ::fcntl(descriptor.get(), F_DUPFD_CLOEXEC, 10);
        if (moved < 0) throw cannotStart("fcntl");
        descriptor.reset(moved);
    };
    int resultPipe[2], outputPipe[2];
    if (::pipe2(resultPipe, O_CLOEXEC) != 0) throw cannotStart("pipe");
    Descriptor resultRead, resultWrite, outputRead, outputWrite;
    resultRead.reset(resultPipe[0]);
    resultWrite.reset(resultPipe[1]);
    if (::pipe2(outputPipe, O_CLOEXEC) != 0) throw cannotStart("pipe");
    outputRead.reset(outputPipe[0]);
    outputWrite.reset(outputPipe[1]);
    Descriptor sceneFile;
    sceneFile.reset(::memfd_create("chaintube-imported-scene", MFD_CLOEXEC));
    if (sceneFile.get() < 0) throw cannotStart("memfd_create");
    above10(resultWrite);
    above10(outputWrite);
    above10(sceneFile);

    // The reader's command line: its own arguments, then the file, this process and the
    // options (see serveAsReaderProgram).
    const auto hex = [](double value) {
        char text[64];
        std::snprintf(text, sizeof text, "%a", value);
        return std::string(text);
    };
    std::vector<std::string> arguments{program.path.string()};
    arguments.insert(arguments.end(), program.arguments.begin(), program.arguments.end());
    arguments.push_back(kProtocol);
    arguments.push_back(file.string());
    arguments.push_back(std::to_string(::getpid()));
    arguments.push_back(options.metresPerUnit ? hex(*options.metresPerUnit) : "-");
    arguments.push_back(!options.upAxis ? "-" : *options.upAxis == UpAxis::PositiveZ ? "z" : "y");
    arguments.push_back(hex(options.chordalTolerance));
    arguments.push_back(hex(options.angularTolerance));
    arguments.push_back(options.progress ? "1" : "0");
    std::vector<char*> argv;
    for (std::string& argument : arguments)
        argv.push_back(argument.data());
    argv.push_back(nullptr);

    // posix_spawn, not fork: the caller may have other threads (the editor imports on a
    // worker), and a forked copy of a multithreaded process may only run async-signal-safe
    // code: a lock another thread held at the fork (an allocator's, the loader's) stays held
    // in the child. A fresh program has no such state.
    posix_spawn_file_actions_t actions;
    posix_spawnattr_t attributes;
    posix_spawn_file_actions_init(&actions);
    posix_spawnattr_init(&attributes);
    struct Release
    {
        posix_spawn_file_actions_t* actions;
        posix_spawnattr_t* attributes;
        ~Release()
        {
            posix_spawn_file_actions_destroy(actions);
            posix_spawnattr_destroy(attributes);
        }
    } release{&actions, &attributes};
    // stdout and stderr go to the parent (assimp's ai_assert messages end up in the error),
    // messages to fd 3, the scene to fd 4, stdin from /dev/null; any descriptor the caller
    // left inheritable is closed.
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_adddup2(&actions, outputWrite.get(), STDOUT_FILENO);
    posix_spawn_file_actions_adddup2(&actions, outputWrite.get(), STDERR_FILENO);
    posix_spawn_file_actions_adddup2(&actions, resultWrite.get(), kResultFd);
    posix_spawn_file_actions_adddup2(&actions, sceneFile.get(), kSceneFd);
    posix_spawn_file_actions_addclosefrom_np(&actions, kSceneFd + 1);
    // Default actions for the crash signals (a caller that ignores SIGPIPE would pass that
    // on), no signal blocked.
    sigset_t defaults, none;
    sigemptyset(&defaults);
    sigemptyset(&none);
    for (const int signal : {SIGABRT, SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGTRAP, SIGSYS, SIGPIPE})
        sigaddset(&defaults, signal);
    posix_spawnattr_setsigdefault(&attributes, &defaults);
    posix_spawnattr_setsigmask(&attributes, &none);
    posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
    pid_t pid = 0;
    if (const int error =
            ::posix_spawn(&pid, program.path.c_str(), &actions, &attributes, argv.data(), environ);
        error != 0)
        throw FileError(file, "cannot start the importer process " + program.path.string() + ": " +
                                  std::strerror(error));
    ChildProcess child(pid);
    resultWrite.reset();
    outputWrite.reset();

    // Read both pipes until the child closes them: the messages (progress, then the answer)
    // and its output. Progress is forwarded as it comes; a cancel from the caller
    // throws Cancelled here and ~ChildProcess kills the child.
    std::string messages, output;
    std::size_t parsed = 0;
    std::size_t finalAt = 0, finalSize = 0;
    char finalType = 0;
    bool messagesOpen = true, outputOpen = true;
    double lastFraction = 0.0;
    // With a progress callback, ask it again every 100 ms even while the reader is silent (assimp
    // reports only between its steps), so that a cancel is honoured at once.
    const int pollMilliseconds = options.progress ? 100 : -1;
    while (messagesOpen || outputOpen) {
        pollfd descriptors[2] = {{messagesOpen ? resultRead.get() : -1, POLLIN, 0},
                                 {outputOpen ? outputRead.get() : -1, POLLIN, 0}};
        const int ready = ::poll(descriptors, 2, pollMilliseconds);
        if (ready < 0) {
            if (errno == EINTR) continue;
            throw FileError(file, std::string("cannot wait for the importer process: ") +
                                      std::strerror(errno));
        }
        if (ready == 0) {
            progress.report(lastFraction); // the same fraction again: the sequence stays sorted
            continue;
        }
        if (descriptors[1].revents != 0)
            outputOpen = readAvailable(outputRead.get(), output, kOutputLimit, file);
        if (descriptors[0].revents == 0) continue;
        messagesOpen = readAvailable(resultRead.get(), messages, SIZE_MAX, file);
        while (finalType == 0 && messages.size() - parsed >= kHeaderSize) {
            std::uint64_t length;
            std::memcpy(&length, messages.data() + parsed + 1, sizeof length);
            if (length > messages.size() - parsed - kHeaderSize) break; // not all here yet
            const char type = messages[parsed];
            const char* payload = messages.data() + parsed + kHeaderSize;
            if (type == kProgress && length == sizeof(double)) {
                double fraction;
                std::memcpy(&fraction, payload, sizeof fraction);
                lastFraction = std::max(lastFraction, fraction);
                progress.report(fraction);
            } else if (type == kResult || type == kRefusal) {
                finalType = type;
                finalAt = parsed + kHeaderSize;
                finalSize = static_cast<std::size_t>(length);
            }
            parsed += kHeaderSize + static_cast<std::size_t>(length);
        }
    }
    const int status = child.waitStatus();

    if (status != -1 && WIFSIGNALED(status)) {
        const std::string said = lastLine(output);
        throw ImportError(file,
                          "the " + readerName + " crashed on malformed data (" +
                              signalName(WTERMSIG(status)) + ")" +
                              (said.empty() ? std::string() : "; it wrote: " + said),
                          WTERMSIG(status), -1, output);
    }
    const int exitStatus = status == -1 ? 0 : (WIFEXITED(status) ? WEXITSTATUS(status) : -1);
    if (exitStatus != 0 || finalType == 0) {
        const std::string said = lastLine(output);
        throw ImportError(file,
                          "the " + readerName + " ended without an answer (exit status " +
                              std::to_string(exitStatus) + ")" +
                              (said.empty() ? std::string() : "; it wrote: " + said),
                          0, exitStatus, output);
    }
    if (finalType == kRefusal) throw FileError(file, messages.substr(finalAt, finalSize));
    std::uint64_t size = 0;
    struct stat sceneStatus
    {
    };
    if (finalSize != sizeof size) Deserialiser(nullptr, 0, file).fail();
    std::memcpy(&size, messages.data() + finalAt, sizeof size);
    if (size == 0 || ::fstat(sceneFile.get(), &sceneStatus) != 0 ||
        size > static_cast<std::uint64_t>(sceneStatus.st_size))
        Deserialiser(nullptr, 0, file).fail();
    void* mapping = ::mmap(nullptr, size, PROT_READ, MAP_SHARED | MAP_POPULATE, sceneFile.get(), 0);
    if (mapping == MAP_FAILED)
        throw FileError(file,
                        std::string("cannot map the imported scene: ") + std::strerror(errno));
    struct Unmap
    {
        void* at;
        std::size_t size;
        ~Unmap() { ::munmap(at, size); }
    } unmap{mapping, static_cast<std::size_t>(size)};
    return deserialise(static_cast<const char*>(mapping), static_cast<std::size_t>(size), file);
}

} // namespace chaintube::formats::detail
