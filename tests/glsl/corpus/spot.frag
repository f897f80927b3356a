#version 300 es
precision mediump float;
const int numLights = 3;
uniform vec4 uLightColors[numLights];
uniform float uLightCutOff;
in vec3 vRay[numLights];
in vec3 vNormals[numLights];
out vec4 fragColor;
struct S { float a; int b; };
void main(void) {
  vec4 Id = vec4(0.0);
  S s = S(1.0, 2);
  for (int i = 0; i < numLights; i++) {
    float l = dot(normalize(vNormals[i]), -normalize(vRay[i]));
    if (l > uLightCutOff) Id += uLightColors[i] * pow(l, 10.0 * uLightCutOff);
    else continue;
    switch (s.b) { case 1: break; default: Id *= 0.5; }
  }
  if (Id.a < 0.0) discard;
  fragColor = vec4(Id.rgb, 1.0);
}
