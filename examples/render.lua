-- render.lua — a mesa with a cliff, rendered three ways: rule colours by
-- altitude and slope, strata from a layered "resistance" field mapped
-- through a palette (bands that show on the cliff, as in Paris et al. 2019's
-- figures), and a Lua colour function; plus an EXR with the AOVs.
--
--   outcrop run examples/render.lua [--set size=640] [--out DIR]

local oc = require "outcrop"

local w = oc.param("size", 640)
local h = w * 9 // 16

-- Ground slab, a mesa of blended boxes, its edges worn by noise.
local ground = oc.box{min = {-120, -120, -40}, max = {120, 120, -2}, falloff = 4}
local mesa = oc.warp(
  oc.box{min = {-40, -25, -10}, max = {40, 25, 30}, falloff = 6},
  {wavelength = 30, amplitude = 3})
local scene = ground + mesa

-- Strata: a field that grows with altitude (a half-space with a long
-- falloff), bent by a warp so the layers fold; mapped through alternating
-- stops of soft and hard rock.
local layers = oc.warp(oc.plane{origin = {0, 0, 60}, normal = {0, 0, -1}, falloff = 120},
                       {wavelength = 90, amplitude = 4})
local palette = {}
local soft, hard = {0.36, 0.20, 0.09}, {0.26, 0.25, 0.23} -- linear albedos
for k = 0, 20 do
  palette[#palette + 1] = {k / 20, k % 2 == 0 and soft or hard}
end

local camera = {eye = {-120, -160, 70}, target = {0, 0, 5}, fov = 35}
local views = {
  {"mesa_rules.png", {rules = {sea_level = -30, snow_line = 60}}},
  {"mesa_strata.png", {color = layers, palette = palette}},
  {"mesa_function.png", {color = function(x, y, z, nx, ny, nz)
    -- red on steep faces, pale on flat ones
    local steep = 1 - nz * nz
    return 0.12 + 0.3 * steep, 0.12, 0.10
  end}},
}
for _, v in ipairs(views) do
  local opts = v[2]
  opts.camera, opts.size = camera, {w, h}
  assert(oc.render(scene, opts):write(v[1]))
  print("render: wrote " .. v[1])
end
assert(oc.render(scene, {camera = camera, size = {w, h}, aov = true}):write("mesa.exr"))
print("render: wrote mesa.exr (R, G, B, A, Z, N, P, evals)")
