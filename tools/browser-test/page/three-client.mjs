// three.js client: loads the model with GLTFLoader (+ MeshoptDecoder), counts what it would draw and, when
// asked to, renders one frame framed on the model's bounding sphere.

import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { MeshoptDecoder } from 'three/addons/libs/meshopt_decoder.module.js';
import { params, viewDirection, FOV_DEGREES, MARGIN, finish, failure } from './common.mjs';

/** Triangles and meshes drawn per frame; a mesh used by several nodes or instances counts every time. */
function countDrawn(root) {
  let triangles = 0;
  let meshes = 0;
  root.traverseVisible((object) => {
    if (!object.isMesh) return; // lines and points are not triangles
    const geometry = object.geometry;
    const total = geometry.index ? geometry.index.count : geometry.attributes.position.count;
    const start = Math.min(geometry.drawRange.start, total);
    const end = Math.min(total, start + geometry.drawRange.count); // count is Infinity by default
    const instances = object.isInstancedMesh ? object.count : 1;
    // GLTFLoader has already turned strips and fans into plain triangle lists.
    triangles += Math.floor((end - start) / 3) * instances;
    meshes += instances;
  });
  return { triangles, meshes };
}

/** Renders one 800x600 frame of `root`, framed by its bounding sphere. */
function render(root, p) {
  const view = document.getElementById('view');
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(1);
  renderer.setSize(view.clientWidth, view.clientHeight);
  view.appendChild(renderer.domElement);

  const scene = new THREE.Scene();
  scene.background = new THREE.Color().setRGB(...p.background.map((c) => c / 255), THREE.SRGBColorSpace);
  scene.add(root);

  const box = new THREE.Box3().setFromObject(root);
  if (box.isEmpty()) throw new Error('the scene has nothing with a bounding box');
  const sphere = box.getBoundingSphere(new THREE.Sphere());
  const radius = Math.max(sphere.radius, 1e-6);
  const aspect = view.clientWidth / view.clientHeight;
  const dir = new THREE.Vector3(...viewDirection(p.azimuth, p.elevation));
  const halfFov = THREE.MathUtils.degToRad(FOV_DEGREES / 2);
  const distance = p.ortho ? 3 * radius : (MARGIN * radius) / Math.sin(halfFov);

  let camera;
  if (p.ortho) {
    const h = MARGIN * radius;
    camera = new THREE.OrthographicCamera(-h * aspect, h * aspect, h, -h, 0.01 * radius, 6 * radius);
  } else {
    camera = new THREE.PerspectiveCamera(FOV_DEGREES, aspect, Math.max(distance - 2 * radius, distance * 1e-3), distance + 2 * radius);
  }
  camera.position.copy(sphere.center).addScaledVector(dir, distance);
  // Looking straight down or up: "up" must not be parallel to the view direction.
  if (Math.abs(dir.y) > 0.999) camera.up.set(0, 0, -Math.sign(dir.y));
  camera.lookAt(sphere.center);
  camera.updateMatrixWorld();

  // Hemisphere light for the shadowed side, one directional light from over the camera's shoulder.
  scene.add(new THREE.HemisphereLight(0xffffff, 0x555555, 1.6));
  const sun = new THREE.DirectionalLight(0xffffff, 2.2);
  const right = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 0);
  const up = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 1);
  sun.position.copy(sphere.center).addScaledVector(dir.clone().add(up.multiplyScalar(0.6)).add(right.multiplyScalar(-0.4)), distance);
  sun.target.position.copy(sphere.center);
  scene.add(sun, sun.target);

  renderer.render(scene, camera);
  return { radius: sphere.radius, center: sphere.center.toArray() };
}

async function main() {
  const p = params();
  const loader = new GLTFLoader().setMeshoptDecoder(MeshoptDecoder);
  const start = performance.now();
  const gltf = await loader.loadAsync(p.model);
  const ms = performance.now() - start;
  const root = gltf.scene ?? gltf.scenes[0];
  root.updateMatrixWorld(true);
  const { triangles, meshes } = countDrawn(root);
  const result = { ok: true, triangles, meshes, ms: Math.round(ms) };
  if (p.render) {
    const renderStart = performance.now();
    result.bounds = render(root, p);
    result.renderMs = Math.round(performance.now() - renderStart);
  }
  return result;
}

main().then(finish, (err) => finish(failure(err)));
