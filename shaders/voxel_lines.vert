// The strand pieces the first shadowed light's voxel pass captured
// (shaders/strand.tese with CAPTURE), drawn as lines from another light for
// its voxel grid: the tessellation runs once for all the lights. Feeds
// voxelize.frag the inputs strand.tese gives it.
#include "common.glsl"

layout(location = 0) in vec3 aWorld;
layout(location = 1) in vec3 aTangent;
layout(location = 2) in float aRadius;
layout(location = 0) out vec3 tWorld;
layout(location = 1) out vec3 tTangent;
layout(location = 2) out float tRadius;

void main() {
    tWorld = aWorld;
    tTangent = aTangent;
    tRadius = aRadius;
    gl_Position = uViewProj * vec4(aWorld, 1.0);
}
