-- layers_ravine.lua — the sweeping tool on material stacks (Peytavie et
-- al. 2009, figures 11 and 12): a plateau of bedrock and a branching
-- ravine swept into it with a non-convex profile (a slot opening into a
-- wider gallery under overhanging walls, then a narrow floor), cut
-- through the block's edge so that the profile shows there. The profile
-- follows the surface (its up vector is the surface normal); the branch
-- narrows towards its end (a second, smaller profile at its last point).
-- Sand poured on the rim spills into the ravine and is stabilised. The
-- picture and the mesh's vertex colours are textured by material.
--
--   outcrop run examples/layers_ravine.lua [--set cell=0.5] [--out DIR]

local oc = require "outcrop"

local cell = oc.param("cell", 0.5)
local nx, ny = math.floor(80 / cell) + 1, math.floor(60 / cell) + 1

-- a gently rolling plateau, 20 m of bedrock over the base
local hf = oc.heightfield.from(function(x, y)
  return 20 + 1.5 * math.sin(x * 0.11) * math.cos(y * 0.09) + 0.04 * x
end, {size = {nx, ny}, cell = cell, origin = {-40, -30}})
local s = oc.layers.from_heightfield(hf, {base = 0})

-- the cross-section (u across, v up from the surface): a slot 6 m wide
-- through the top 4 m, a gallery 14 m wide under it, a 4 m wide floor
local main = {{-3, 2}, {3, 2}, {3, -4}, {7, -6}, {6.5, -11}, {2, -13},
              {2, -16}, {-2, -16}, {-2, -13}, {-6.5, -11}, {-7, -6},
              {-3, -4}}
-- the branch's end: the same shape at half the size
local small = {}
for k, p in ipairs(main) do small[k] = {0.5 * p[1], 0.5 * p[2] + 1} end

local t0 = os.clock()
local dv, res = s:sweep{
  path = {{{-36, -8}, {-20, -2}, {-5, -6}, {10, 2}, {30, 4}, {46, 6}},
          {{-5, -6}, {2, -16}, {6, -26, profile = 2}}},
  profiles = {main, small},
  mode = "crack",
  stabilize = false}
local added, r2 = s:deposit{center = {-12, 1}, radius = 9, amount = 4,
                            stabilize = {tolerance = 0.005}}
print(string.format("layers_ravine: %.0f m^3 of bedrock carved, %.0f m^3 " ..
                    "of sand stabilised in %d passes (%.1f s CPU)", -dv,
                    added, r2.iterations, os.clock() - t0))
local st = s:stats()
print(string.format("layers_ravine: %d stacks, %d layers, %d bytes",
                    st.stacks, st.layers, st.bytes))

local box = {-40, -30, 0, 40, 30, 26}
-- sigma two cells: a smoother surface than one cell's on the slot's rim
local solid = s:field{materials = {"bedrock", "sand"}, sigma = 2 * cell}
local mesh = oc.polygonize(solid, {box = box, cell = cell})
-- textured by material (section 6): each material's colour and triplanar
-- texture, blended by its share of the box of half-side 2 cells around
local colors = s:colors{bedrock = {0.30, 0.22, 0.17}}
mesh:write("layers_ravine.ply", {colors = colors})
print(string.format("layers_ravine: %d triangles", mesh:stats().triangles))
oc.render(solid, {camera = {eye = {78, -36, 42}, target = {10, 0, 8},
                            fov = 40},
                  size = {800, 450},
                  color = colors}):write("layers_ravine.png")
print("layers_ravine: wrote layers_ravine.ply, layers_ravine.png")
