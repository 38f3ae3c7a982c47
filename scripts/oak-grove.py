# A real-foliage test scene: a grove of nine oaks (SaschaWillems/Vulkan-Assets, models/oaktree.gltf:
# double-sided leaf cards, alpha-blended, their vertex normals a median 60° off the cards' faces)
# on an 80 m ground, the sun 45° high, the camera 1 m up (near) or 70 m back and 6 m up (far:
# trees about 60 pixels tall). Usage: scripts/oak-grove.py OAKTREE.gltf OUT.gltf [near|far]
# Then: umbra compare OUT.gltf --size 640x360 --shadow-method exact (docs/exact-shadows.md).
import json, struct, base64, math, random, sys
src = json.load(open(sys.argv[1]))
out, mode = sys.argv[2], (sys.argv[3] if len(sys.argv) > 3 else 'near')
d = json.loads(json.dumps(src))
# ground quad, 80 m, y = 0
S = 40.0
pos = [-S,0,-S, S,0,-S, S,0,S, -S,0,S]
nrm = [0,1,0]*4
idx = [0,2,1, 0,3,2]
blob = struct.pack('12f', *pos) + struct.pack('12f', *nrm) + struct.pack('6H', *idx) + b'\0\0'
bi = len(d['buffers'])
d['buffers'].append({'byteLength': len(blob), 'uri': 'data:application/octet-stream;base64,' + base64.b64encode(blob).decode()})
bv0 = len(d['bufferViews'])
d['bufferViews'] += [{'buffer': bi, 'byteOffset': 0, 'byteLength': 48}, {'buffer': bi, 'byteOffset': 48, 'byteLength': 48}, {'buffer': bi, 'byteOffset': 96, 'byteLength': 12}]
a0 = len(d['accessors'])
d['accessors'] += [{'bufferView': bv0, 'componentType': 5126, 'count': 4, 'type': 'VEC3', 'min': [-S,0,-S], 'max': [S,0,S]},
                   {'bufferView': bv0+1, 'componentType': 5126, 'count': 4, 'type': 'VEC3'},
                   {'bufferView': bv0+2, 'componentType': 5123, 'count': 6, 'type': 'SCALAR'}]
mi = len(d['materials'])
d['materials'].append({'name': 'ground', 'pbrMetallicRoughness': {'baseColorFactor': [0.45, 0.5, 0.35, 1], 'metallicFactor': 0, 'roughnessFactor': 1}})
gm = len(d['meshes'])
d['meshes'].append({'name': 'ground', 'primitives': [{'attributes': {'POSITION': a0, 'NORMAL': a0+1}, 'indices': a0+2, 'material': mi}]})
nodes = [{'mesh': gm, 'name': 'ground'}]
rng = random.Random(7)
trees = []
for i in range(9):
    x, z = rng.uniform(-9, 9), rng.uniform(-16, -2)
    s = rng.uniform(4.5, 6.5)
    a = rng.uniform(0, 2*math.pi)
    # yaw a, then the model's own +90 deg about X
    qy = [0, math.sin(a/2), 0, math.cos(a/2)]
    qx = [0.7071068, 0, 0, 0.7071068]
    # q = qy * qx
    x1,y1,z1,w1 = qy; x2,y2,z2,w2 = qx
    q = [w1*x2 + x1*w2 + y1*z2 - z1*y2, w1*y2 - x1*z2 + y1*w2 + z1*x2, w1*z2 + x1*y2 - y1*x2 + z1*w2, w1*w2 - x1*x2 - y1*y2 - z1*z2]
    for m in (0, 1):
        nodes.append({'mesh': m, 'name': f'oak{i}.{m}', 'translation': [x, 0, z], 'rotation': q, 'scale': [s, s, s]})
# sun 45 deg high
el, az = math.radians(45), math.radians(35)
dirn = [math.cos(el)*math.sin(az), -math.sin(el), math.cos(el)*math.cos(az)]  # light travels along -Z of its node
# rotation taking -Z to dirn
fz = [-v for v in dirn]
up = [0,1,0]
def cross(a,b): return [a[1]*b[2]-a[2]*b[1], a[2]*b[0]-a[0]*b[2], a[0]*b[1]-a[1]*b[0]]
def norm(v): l = math.sqrt(sum(c*c for c in v)); return [c/l for c in v]
def quat_from_basis(xa, ya, za):
    m00,m01,m02 = xa[0],ya[0],za[0]; m10,m11,m12 = xa[1],ya[1],za[1]; m20,m21,m22 = xa[2],ya[2],za[2]
    t = m00+m11+m22
    if t > 0:
        s = math.sqrt(t+1)*2; return [(m21-m12)/s, (m02-m20)/s, (m10-m01)/s, 0.25*s]
    if m00 > m11 and m00 > m22:
        s = math.sqrt(1+m00-m11-m22)*2; return [0.25*s, (m01+m10)/s, (m02+m20)/s, (m21-m12)/s]
    if m11 > m22:
        s = math.sqrt(1+m11-m00-m22)*2; return [(m01+m10)/s, 0.25*s, (m12+m21)/s, (m02-m20)/s]
    s = math.sqrt(1+m22-m00-m11)*2; return [(m02+m20)/s, (m12+m21)/s, 0.25*s, (m10-m01)/s]
xa = norm(cross(up, fz)); ya = cross(fz, xa)
d.setdefault('extensions', {})['KHR_lights_punctual'] = {'lights': [{'type': 'directional', 'intensity': 3, 'color': [1, 0.97, 0.9]}]}
d['extensionsUsed'] = ['KHR_lights_punctual']
nodes.append({'name': 'sun', 'rotation': quat_from_basis(xa, ya, fz), 'extensions': {'KHR_lights_punctual': {'light': 0}}})
# camera 1 m high looking at the trees (near) or from 60 m back and 6 m up (far: leaves below a pixel)
eye, tgt = ([0, 1.0, 6.0], [0, 2.5, -8.0]) if mode == 'near' else ([0, 6.0, 70.0], [0, 2.0, -8.0])
f = norm([t-e for t, e in zip(tgt, eye)]); cz = [-v for v in f]
cx = norm(cross(up, cz)); cy = cross(cz, cx)
d['cameras'] = [{'type': 'perspective', 'perspective': {'yfov': math.radians(55 if mode == 'near' else 20), 'znear': 0.05, 'aspectRatio': 16/9}}]
nodes.append({'name': 'camera', 'camera': 0, 'translation': eye, 'rotation': quat_from_basis(cx, cy, cz)})
d['nodes'] = nodes
d['scenes'] = [{'name': 'forest', 'nodes': list(range(len(nodes)))}]
d['scene'] = 0
json.dump(d, open(out, 'w'))
print(out, len(nodes), 'nodes')
