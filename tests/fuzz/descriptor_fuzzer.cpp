// libFuzzer target: the runtime descriptor reader (rig::parseDescriptor). Malformed input must
// throw chaintube::Error (DescriptorError); an accepted descriptor must rebuild its hoses.
#include <chaintube/export/rig_descriptor.h>
#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    try {
        const chaintube::rig::HoseRigDescriptor descriptor =
            chaintube::rig::parseDescriptor(text, "fuzz.hoses.json");
        for (const chaintube::rig::RigHose& hose : descriptor.hoses)
            static_cast<void>(chaintube::rig::rebuildHose(hose));
        // What was accepted must serialise and read back to the same text.
        const std::string canonical = chaintube::rig::serialiseDescriptor(descriptor);
        if (chaintube::rig::serialiseDescriptor(
                chaintube::rig::parseDescriptor(canonical, "fuzz.hoses.json")) != canonical)
            __builtin_trap();
    } catch (const chaintube::Error&) {
    }
    return 0;
}
