// Generated hair: a head vertex (position, normal) of a region triangle.
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 0) out vec3 vPosition;
layout(location = 1) out vec3 vNormal;

void main() {
    vPosition = aPosition;
    vNormal = aNormal;
}
