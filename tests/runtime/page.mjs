// The page render.mjs drives: loads one glTF with three.js's GLTFLoader (KTX2 through KTX2Loader
// and its Basis transcoder, meshopt through MeshoptDecoder), renders it from fixed views under a fixed
// light and returns the renders with what three.js made of each texture.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { KTX2Loader } from 'three/addons/loaders/KTX2Loader.js';
import { MeshoptDecoder } from 'three/addons/libs/meshopt_decoder.module.js';
import { RoomEnvironment } from 'three/addons/environments/RoomEnvironment.js';

// three.js material property → the glTF slot it was read from.
const SLOTS = {
  map: 'baseColorTexture',
  emissiveMap: 'emissiveTexture',
  normalMap: 'normalTexture',
  aoMap: 'occlusionTexture',
  roughnessMap: 'metallicRoughnessTexture',
  metalnessMap: 'metallicRoughnessTexture',
};

const FILTERS = {
  [THREE.NearestFilter]: 'nearest',
  [THREE.LinearFilter]: 'linear',
  [THREE.NearestMipmapNearestFilter]: 'nearest_mipmap_nearest',
  [THREE.LinearMipmapNearestFilter]: 'linear_mipmap_nearest',
  [THREE.NearestMipmapLinearFilter]: 'nearest_mipmap_linear',
  [THREE.LinearMipmapLinearFilter]: 'linear_mipmap_linear',
};

function describeTextures(gltf) {
  const seen = new Set();
  const out = [];
  gltf.scene.traverse((object) => {
    if (!object.isMesh) return;
    for (const material of [object.material].flat()) {
      for (const [property, slot] of Object.entries(SLOTS)) {
        const texture = material[property];
        if (!texture || seen.has(`${material.uuid}/${slot}`)) continue;
        seen.add(`${material.uuid}/${slot}`);
        const association = gltf.parser.associations.get(texture);
        out.push({
          material: material.name,
          slot,
          texture: association && association.textures !== undefined ? association.textures : -1,
          colorSpace: texture.colorSpace,
          compressed: Boolean(texture.isCompressedTexture),
          width: texture.image ? texture.image.width : 0,
          height: texture.image ? texture.image.height : 0,
          levels: texture.mipmaps && texture.mipmaps.length ? texture.mipmaps.length : 1,
          generateMipmaps: texture.generateMipmaps,
          minFilter: FILTERS[texture.minFilter] || String(texture.minFilter),
          flipY: texture.flipY,
        });
      }
    }
  });
  return out;
}

// Views along one fixed direction: the whole scene fitted to the frame, nearer (texels magnified)
// and far (the small mip levels).
const VIEWS = { fit: 1.0, near: 0.55, far: 2.5 };

// One renderer, loader and environment for every model of a run: SwiftShader makes each costly.
let context = null;
function contextOf(size) {
  if (context) return context;
  const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
  renderer.setPixelRatio(1);
  renderer.setSize(size, size);
  renderer.outputColorSpace = THREE.SRGBColorSpace;
  renderer.toneMapping = THREE.NoToneMapping;
  document.body.appendChild(renderer.domElement);
  const ktx2 = new KTX2Loader().setTranscoderPath('/three/examples/jsm/libs/basis/').detectSupport(renderer);
  const loader = new GLTFLoader().setKTX2Loader(ktx2).setMeshoptDecoder(MeshoptDecoder);
  const environment = new THREE.PMREMGenerator(renderer).fromScene(new RoomEnvironment(), 0.04).texture;
  context = { renderer, loader, environment };
  return context;
}

async function render(url, size) {
  const { renderer, loader, environment } = contextOf(size);
  const gltf = await loader.loadAsync(url);

  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0.5, 0.5, 0.5);
  scene.environment = environment;
  const sun = new THREE.DirectionalLight(0xffffff, 2.0);
  sun.position.set(0.5, 1.0, 0.75);
  scene.add(sun);
  scene.add(gltf.scene);

  const sphere = new THREE.Box3().setFromObject(gltf.scene).getBoundingSphere(new THREE.Sphere());
  const camera = new THREE.PerspectiveCamera(40, 1, sphere.radius * 0.01, sphere.radius * 20);
  const direction = new THREE.Vector3(0.6, 0.45, 1.0).normalize();
  const fitDistance = sphere.radius / Math.sin(THREE.MathUtils.degToRad(20));
  const images = {};
  for (const [view, scale] of Object.entries(VIEWS)) {
    camera.position.copy(sphere.center).addScaledVector(direction, fitDistance * scale);
    camera.lookAt(sphere.center);
    renderer.render(scene, camera);
    images[view] = renderer.domElement.toDataURL('image/png');
  }
  const textures = describeTextures(gltf);
  gltf.scene.traverse((object) => {
    if (!object.isMesh) return;
    object.geometry.dispose();
    for (const material of [object.material].flat()) {
      for (const property of Object.keys(SLOTS)) if (material[property]) material[property].dispose();
      material.dispose();
    }
  });
  return { images, textures };
}

window.matbakeRender = render;
window.matbakeReady = true;
