#version 300 es
uniform float uSize;
void main() {
  gl_PointSize = uSize;
  gl_Position = vec4(float(gl_VertexID), 0.0, 0.0, 1.0);
}
