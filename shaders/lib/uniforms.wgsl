// The uniforms as the scene shader's functions read them: private copies of the frame's values,
// the material, the immediates and the first light and shadow view, which each entry point fills
// first, from the blocks or from flat inputs (`FlatOut`). Included by scene.wgsl after its
// bindings and `VsOut`.

// What the shaders read of the frame block, bar its arrays of lights and shadow views.
struct FrameValues {
    clip_from_world: mat4x4<f32>,
    world_from_clip: mat4x4<f32>,
    camera_position: vec4<f32>,
    ambient_sky: vec4<f32>,
    ambient_ground: vec4<f32>,
    shadow: vec4<f32>,
    shadow_light: vec4<f32>,
    bias: vec4<f32>,
    camera_forward: vec4<f32>,
    eye_forward: vec4<f32>,
    modes: vec4<u32>,
    output: vec4<f32>,
}

// The uniforms every function reads: the frame's values, the material, the immediates, and the
// frame's first light and shadow view (`light_at`, `view_at`). Each entry point fills them first.
// llvmpipe (Mesa 22.3) loads a uniform in a fragment shader lane by lane, with a bounds check on
// each lane (it cannot assume lane 0 is active): about 15 instructions per scalar for every 8
// pixels, where a flat input is one broadcast. So the entry points of full-screen and
// large-triangle draws (`FlatOut`) take them as flat inputs their vertex shader wrote
// (`load_flat`); the others copy them from the blocks (`load_uniforms`), which compiles to the
// loads they made before.
var<private> frame: FrameValues;
var<private> material: Material;
var<private> pc: Immediates;
var<private> sun: Light;
var<private> view0: ShadowView;

fn load_uniforms() {
    load_frame();
    load_material();
    load_immediates();
}

// The frame's values (set 0, bound for every camera pipeline).
fn load_frame() {
    frame = FrameValues(frame_block.clip_from_world, frame_block.world_from_clip, frame_block.camera_position,
        frame_block.ambient_sky, frame_block.ambient_ground, frame_block.shadow, frame_block.shadow_light,
        frame_block.bias, frame_block.camera_forward, frame_block.eye_forward, frame_block.modes, frame_block.output);
    sun = frame_block.lights[0];
    view0 = frame_block.views[0];
}

// The draw's material (set 1: pipelines that read it bind it).
fn load_material() {
    material = material_block;
}

// The draw's immediates (pushed before each draw; full-screen passes read none).
fn load_immediates() {
    pc = pc_block;
}

// Light i of the frame (under ONE_SUN the only light, 0, is `sun`).
fn light_at(i: u32) -> Light {
    if ONE_SUN {
        return sun;
    }
    return frame_block.lights[i];
}

// Shadow view `layer` (without MANY_VIEWS the only one, 0, is `view0`).
fn view_at(layer: i32) -> ShadowView {
    if !MANY_VIEWS {
        return view0;
    }
    return frame_block.views[layer];
}

// A vertex of a draw whose fragments read the uniforms as flat inputs (see `load_uniforms`):
// VsOut's varyings, then what the lit entry points read per pixel. The frame's clip_from_world
// and camera_forward, the first light's cone and shadow fields and the material's cutoffs and
// texture transforms stay in the blocks (the vertex shader, cascades, spot lights, masked and
// textured materials read them): 31 locations of lavapipe's 32.
struct FlatOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(perspective, centroid) world_position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec4<f32>,
    @location(3) tangent: vec4<f32>,
    @location(4) color: vec4<f32>,
    @location(5) @interpolate(flat) world_from_clip_0: vec4<f32>,
    @location(6) @interpolate(flat) world_from_clip_1: vec4<f32>,
    @location(7) @interpolate(flat) world_from_clip_2: vec4<f32>,
    @location(8) @interpolate(flat) world_from_clip_3: vec4<f32>,
    @location(9) @interpolate(flat) camera_position: vec4<f32>,
    @location(10) @interpolate(flat) ambient_sky: vec4<f32>,
    @location(11) @interpolate(flat) ambient_ground: vec4<f32>,
    @location(12) @interpolate(flat) shadow: vec4<f32>,
    @location(13) @interpolate(flat) shadow_light: vec4<f32>,
    @location(14) @interpolate(flat) bias: vec4<f32>,
    @location(15) @interpolate(flat) eye_forward: vec4<f32>,
    @location(16) @interpolate(flat) modes: vec4<u32>,
    @location(17) @interpolate(flat) output: vec4<f32>,
    @location(18) @interpolate(flat) sun_position: vec4<f32>,
    @location(19) @interpolate(flat) sun_direction: vec4<f32>,
    @location(20) @interpolate(flat) sun_color: vec4<f32>,
    @location(21) @interpolate(flat) view0_clip_0: vec4<f32>,
    @location(22) @interpolate(flat) view0_clip_1: vec4<f32>,
    @location(23) @interpolate(flat) view0_clip_2: vec4<f32>,
    @location(24) @interpolate(flat) view0_clip_3: vec4<f32>,
    @location(25) @interpolate(flat) view0_rect: vec4<f32>,
    @location(26) @interpolate(flat) view0_cascade: vec4<f32>,
    @location(27) @interpolate(flat) base_color: vec4<f32>,
    @location(28) @interpolate(flat) emissive: vec4<f32>,
    @location(29) @interpolate(flat) params: vec4<f32>,
    @location(30) @interpolate(flat) normal_y: vec4<f32>,
}

// Vertex `v` with the frame's values (after `load_frame`; the material's and `normal_y` are zero).
fn flat_out(v: VsOut) -> FlatOut {
    var out: FlatOut;
    out.clip = v.clip;
    out.world_position = v.world_position;
    out.normal = v.normal;
    out.uv = v.uv;
    out.tangent = v.tangent;
    out.color = v.color;
    out.world_from_clip_0 = frame.world_from_clip[0];
    out.world_from_clip_1 = frame.world_from_clip[1];
    out.world_from_clip_2 = frame.world_from_clip[2];
    out.world_from_clip_3 = frame.world_from_clip[3];
    out.camera_position = frame.camera_position;
    out.ambient_sky = frame.ambient_sky;
    out.ambient_ground = frame.ambient_ground;
    out.shadow = frame.shadow;
    out.shadow_light = frame.shadow_light;
    out.bias = frame.bias;
    out.eye_forward = frame.eye_forward;
    out.modes = frame.modes;
    out.output = frame.output;
    out.sun_position = sun.position;
    out.sun_direction = sun.direction;
    out.sun_color = sun.color;
    out.view0_clip_0 = view0.clip[0];
    out.view0_clip_1 = view0.clip[1];
    out.view0_clip_2 = view0.clip[2];
    out.view0_clip_3 = view0.clip[3];
    out.view0_rect = view0.rect;
    out.view0_cascade = view0.cascade;
    return out;
}

// `vertex` with the material's values (after `load_material`).
fn with_material(vertex: FlatOut) -> FlatOut {
    var out = vertex;
    out.base_color = material.base_color;
    out.emissive = material.emissive;
    out.params = material.params;
    return out;
}

// Fills the material from flat inputs (and its block for the rest).
fn load_flat_material(in: FlatOut) {
    material = material_block;
    material.base_color = in.base_color;
    material.emissive = in.emissive;
    material.params = in.params;
}

// Fills the frame's values from flat inputs (and the block for the rest); returns the varyings.
fn load_flat(in: FlatOut) -> VsOut {
    frame = FrameValues(frame_block.clip_from_world,
        mat4x4<f32>(in.world_from_clip_0, in.world_from_clip_1, in.world_from_clip_2, in.world_from_clip_3),
        in.camera_position, in.ambient_sky, in.ambient_ground, in.shadow, in.shadow_light, in.bias,
        frame_block.camera_forward, in.eye_forward, in.modes, in.output);
    // The only immediate a lit fragment shader reads (the viewer's highlight).
    pc.normal_y = in.normal_y;
    sun = Light(in.sun_position, in.sun_direction, in.sun_color, frame_block.lights[0].cone, frame_block.lights[0].shadow);
    view0 = ShadowView(mat4x4<f32>(in.view0_clip_0, in.view0_clip_1, in.view0_clip_2, in.view0_clip_3), in.view0_rect,
        in.view0_cascade);
    var v: VsOut;
    v.clip = in.clip;
    v.world_position = in.world_position;
    v.normal = in.normal;
    v.uv = in.uv;
    v.tangent = in.tangent;
    v.color = in.color;
    return v;
}
