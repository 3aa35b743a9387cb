// Simulated strands: one vertex of a polyline (xyz position, w radius).
layout(location = 0) in vec4 aPoint;
out vec4 vPoint;

void main() {
    vPoint = aPoint;
}
