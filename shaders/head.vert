// The head mesh (camera pass and the light's shadow-map pass).
#include "common.glsl"

layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 0) out vec3 vWorld;
layout(location = 1) out vec3 vNormal;

void main() {
    vWorld = aPosition;
    vNormal = aNormal;
    gl_Position = uViewProj * vec4(aPosition, 1.0);
}
