#define N 3
#define SQ(x) ((x) * (x))
#if defined(N) && N > 2
precision highp float;
#else
#error no
#endif
uniform vec4 u[N];
void main() {
    vec4 s = vec4(0.0);
    for (int i = 0; i < N; i++) s += SQ(u[i]);
    gl_FragColor = s;
}
