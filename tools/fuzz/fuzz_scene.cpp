// libFuzzer target: scene YAML through the schema walk and the load-time
// budget checks Scene::parse runs (pipeline/scene/scene.h, pipeline/scene/scene_budget.h). Every input must
// load or throw one of hairpipe's errors (SceneError/AssetError): a crash, a
// sanitizer report or another exception type (a YAML::Exception leaking out)
// is a bug. The scene's folder does not exist, so File keys fail cleanly
// instead of probing the machine.
#include "tools/fuzz/fuzz_target.h"

#include "core/errors.h"
#include "pipeline/scene/scene.h"

#include <string>

HP_FUZZ_TARGET(scene)(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        const hp::Scene scene = hp::Scene::parse(text, "fuzz.yaml", "/nonexistent/hairpipe-fuzz");
        (void)scene.dump();
    } catch (const hp::Error&) {
    }
    return 0;
}
