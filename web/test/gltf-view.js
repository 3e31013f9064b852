// A minimal three.js viewer for the browser test: loads the .glb embedded in the page
// (base64 in #glb), plays its animation to the middle, frames it and draws it once; sets
// body[data-ready] and window.__gltfStats (meshes, distinct colours on the canvas).
import * as THREE from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';

const canvas = document.getElementById('view');
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
renderer.setClearColor(0xe8edf3);
const scene = new THREE.Scene();
scene.add(new THREE.HemisphereLight(0xffffff, 0x8a8a80, 2.2));
const sun = new THREE.DirectionalLight(0xffffff, 2.0);
sun.position.set(3, 6, 4);
scene.add(sun);
const bytes = Uint8Array.from(atob(document.getElementById('glb').textContent.trim()), (c) => c.charCodeAt(0));
new GLTFLoader().parse(bytes.buffer, '', (gltf) => {
  scene.add(gltf.scene);
  const mixer = new THREE.AnimationMixer(gltf.scene);
  const clip = gltf.animations[0];
  if (clip) {
    mixer.clipAction(clip).play();
    mixer.setTime(clip.duration / 2);
  }
  gltf.scene.updateMatrixWorld(true);
  const box = new THREE.Box3().setFromObject(gltf.scene);
  const centre = box.getCenter(new THREE.Vector3());
  const size = box.getSize(new THREE.Vector3()).length();
  const camera = new THREE.PerspectiveCamera(35, canvas.width / canvas.height, 0.05, 100);
  // Three-quarters from the front right (glTF: +X forward of the characters, +Z their right).
  camera.position.copy(centre).add(new THREE.Vector3(0.7, 0.45, 1.0).normalize().multiplyScalar(1.1 * size));
  camera.lookAt(centre);
  const grid = new THREE.GridHelper(40, 80, 0x9aa3ad, 0xc8cdd3);
  grid.position.y = 0;
  scene.add(grid);
  renderer.render(scene, camera);
  const copy = document.createElement('canvas');
  copy.width = canvas.width;
  copy.height = canvas.height;
  const g = copy.getContext('2d');
  g.drawImage(canvas, 0, 0);
  const px = g.getImageData(0, 0, copy.width, copy.height).data;
  const colours = new Set();
  for (let i = 0; i < px.length && colours.size < 5000; i += 4) colours.add((px[i] << 16) | (px[i + 1] << 8) | px[i + 2]);
  let meshes = 0;
  gltf.scene.traverse((o) => { if (o.isMesh) meshes++; });
  window.__gltfStats = { meshes, colours: colours.size };
  document.body.dataset.ready = '1';
}, (e) => { console.error(String(e)); });
