-- layers_caves.lua — material stacks (Peytavie et al. 2009, figure 20):
-- two caves linked by tunnels, opening into a chasm spanned by a stone
-- bridge, with piles of rocks in the chasm. The rock mass is an implicit
-- tree (a block, the chasm, the caves and tunnels carved, the bridge
-- left) turned into stacks by from_node (caves, tunnels and the space
-- under the bridge are air layers between bedrock layers); rocks and sand
-- are poured into the chasm and stabilised at their angles of repose;
-- the rocks layer is then filled with rocks from a tile of eroded
-- Voronoi cells (section 5), placed where the layer is and culled
-- below twice the largest rock radius.
--
--   outcrop run examples/layers_caves.lua [--set cell=0.5] [--out DIR]

local oc = require "outcrop"

local cell = oc.param("cell", 0.5)
local T = oc.threshold

-- the rock: a block with a chasm through it along y
local mass = oc.box{min = {-30, -30, -12}, max = {30, 30, 14}, falloff = 1}
local chasm = oc.box{min = {-7, -40, 0}, max = {7, 40, 40}, falloff = 3}
-- the bridge: a slab across the chasm, its underside arched
local slab = oc.box{min = {-10, 2, 9}, max = {10, 8, 13}, falloff = 1}
local arch = oc.segment{a = {0, -5, 1}, b = {0, 15, 1}, radius = 9}
local bridge = oc.difference(slab, arch)
-- the caves, one in each wall, each opening into the chasm by a tunnel;
-- a third tunnel under the chasm's floor links them
local caves = oc.union{
  oc.sphere{center = {-19, 4, 5}, radius = 6.5},
  oc.sphere{center = {18, -8, 3}, radius = 6},
  oc.segment{a = {-19, 4, 5}, b = {-5, -12, 6}, radius = 2.8},
  oc.segment{a = {18, -8, 2}, b = {5, 16, 5}, radius = 2.6},
  oc.segment{a = {-19, 4, -1}, b = {18, -8, -2}, radius = 2.2}}
local rock = oc.union{oc.difference(oc.difference(mass, chasm), caves), bridge}

local box = {-28, -28, -10, 28, 28, 16}
local s = oc.layers.from_node(rock, {box = box, cell = cell})
local st = s:stats()
print(string.format("layers_caves: %d stacks, %d layers, %d bytes", st.stacks,
                    st.layers, st.bytes))

-- rocks, then sand, poured into the chasm; each stabilised
local t0 = os.clock()
local stab = {tolerance = 0.005}
local piles = {{2, -22, 6, 5}, {2, -4, 5, 4}, {-1, 10, 6, 5}, {-2, 23, 5, 4}}
local moved, passes = 0, 0
for _, p in ipairs(piles) do
  local a, r = s:deposit{center = {p[1], p[2]}, radius = p[3], amount = p[4],
                         material = "rocks", stabilize = stab}
  moved, passes = moved + a, passes + r.iterations
end
local a, r = s:deposit{center = {2, -2}, radius = 9, amount = 1.5,
                       stabilize = stab}
print(string.format("layers_caves: %.0f m^3 of rocks and %.0f m^3 of sand, " ..
                    "stabilised in %d passes (%.2f s CPU)", moved, a,
                    passes + r.iterations, os.clock() - t0))

-- the rocks: a tile of eroded Voronoi cells placed in the rocks layer
t0 = os.clock()
local tile = oc.layers.rocks{size = 6, radius = 1.3, seed = 20}
local ground = s:field{materials = {"bedrock", "sand"}}
local scene, info = s:rocks(tile, {ground = ground})
print(string.format("layers_caves: %d rocks in the tile, %d placed " ..
                    "(depth %.2f m) in %.2f s CPU", tile:count(),
                    info.instances, info.depth, os.clock() - t0))

-- colours: rocks grey, sand ochre, bedrock the warm grey of limestone
local sand = s:field{materials = {"sand"}}
local function color(x, y, z)
  local p = {x, y, z}
  if ground:eval(p) < 0.8 * T then return 0.16, 0.16, 0.16 end
  if sand:eval(p) > 0.5 * T then return 0.45, 0.34, 0.18 end
  return 0.30, 0.22, 0.16
end
oc.render(scene, {camera = {eye = {8, -62, 36}, target = {0, 0, 2}, fov = 40},
                  size = {800, 450}, sun = {direction = {0.55, -0.45, 0.7}},
                  color = color}):write("layers_caves.png")
print("layers_caves: wrote layers_caves.png")
