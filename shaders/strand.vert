// Simulated strands: one vertex of a polyline (xyz position, w radius).
layout(location = 0) in vec4 aPoint;
out vec4 vPoint;
out float vIndex;  // the vertex's index (exact in a float below 2^24 vertices)

void main() {
    vPoint = aPoint;
    vIndex = float(gl_VertexID);
}
