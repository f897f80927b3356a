// A small 4x4 matrix helper for the lesson pages, written for these tests. Matrices are
// Float32Arrays in column-major order, as uniformMatrix4fv takes them; each operation works in
// double precision and stores single precision, like the common JavaScript matrix libraries.
const mat4 = {
  identity() {
    const m = new Float32Array(16);
    m[0] = m[5] = m[10] = m[15] = 1;
    return m;
  },
  perspective(fovy, aspect, near, far) {
    const f = 1.0 / Math.tan(fovy / 2);
    const m = new Float32Array(16);
    m[0] = f / aspect;
    m[5] = f;
    m[10] = (far + near) / (near - far);
    m[11] = -1;
    m[14] = 2 * far * near / (near - far);
    return m;
  },
  lookAt(eye, center, up) {
    let fx = center[0] - eye[0], fy = center[1] - eye[1], fz = center[2] - eye[2];
    let len = Math.hypot(fx, fy, fz);
    fx /= len; fy /= len; fz /= len;
    // s = f x up, normalised; u = s x f
    let sx = fy * up[2] - fz * up[1], sy = fz * up[0] - fx * up[2], sz = fx * up[1] - fy * up[0];
    len = Math.hypot(sx, sy, sz);
    sx /= len; sy /= len; sz /= len;
    const ux = sy * fz - sz * fy, uy = sz * fx - sx * fz, uz = sx * fy - sy * fx;
    const m = new Float32Array(16);
    m[0] = sx; m[4] = sy; m[8] = sz;
    m[1] = ux; m[5] = uy; m[9] = uz;
    m[2] = -fx; m[6] = -fy; m[10] = -fz;
    m[12] = -(sx * eye[0] + sy * eye[1] + sz * eye[2]);
    m[13] = -(ux * eye[0] + uy * eye[1] + uz * eye[2]);
    m[14] = fx * eye[0] + fy * eye[1] + fz * eye[2];
    m[15] = 1;
    return m;
  },
  translation(x, y, z) {
    const m = mat4.identity();
    m[12] = x; m[13] = y; m[14] = z;
    return m;
  },
  multiply(a, b) {
    const out = new Float32Array(16);
    for (let col = 0; col < 4; col++) {
      for (let row = 0; row < 4; row++) {
        let sum = 0;
        for (let k = 0; k < 4; k++) sum += a[k * 4 + row] * b[col * 4 + k];
        out[col * 4 + row] = sum;
      }
    }
    return out;
  },
  // The inverse transpose, for normals: cofactors over the determinant.
  normalMatrix(m) {
    const a = Array.from(m);
    const inv = new Array(16);
    const minor = (r, c) => {
      const rows = [0, 1, 2, 3].filter((i) => i !== r), cols = [0, 1, 2, 3].filter((j) => j !== c);
      const e = (i, j) => a[cols[j] * 4 + rows[i]];
      return e(0, 0) * (e(1, 1) * e(2, 2) - e(1, 2) * e(2, 1))
           - e(0, 1) * (e(1, 0) * e(2, 2) - e(1, 2) * e(2, 0))
           + e(0, 2) * (e(1, 0) * e(2, 1) - e(1, 1) * e(2, 0));
    };
    let det = 0;
    for (let c = 0; c < 4; c++) det += a[c * 4] * ((c % 2) ? -1 : 1) * minor(0, c);
    const out = new Float32Array(16);
    // (M^-1)^T [r][c] = cofactor(r, c) / det
    for (let r = 0; r < 4; r++) for (let c = 0; c < 4; c++) out[c * 4 + r] = (((r + c) % 2) ? -1 : 1) * minor(r, c) / det;
    return out;
  },
};
