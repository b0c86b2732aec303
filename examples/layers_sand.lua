-- layers_sand.lua — material stacks (Peytavie et al. 2009, figures 13 and
-- 23): a cliff block with an arch carved through it, turned into stacks
-- of bedrock and air (the arch's opening is an air layer under a bedrock
-- roof), then sand poured beside and on top of the cliff and stabilised
-- at its angle of repose: the sand on the cliff spills over its edge and
-- piles at the foot. The surface is the convolution of the bedrock and
-- sand layers; the picture is coloured by the sand's own convolution.
--
--   outcrop run examples/layers_sand.lua [--set cell=0.5] [--out DIR]

local oc = require "outcrop"

local cell = oc.param("cell", 0.5)

-- the rock: a ground slab and a cliff with an arch through it
local ground = oc.box{min = {-40, -30, -12}, max = {40, 30, 0}, falloff = 1}
local cliff = oc.box{min = {-10, -26, -1}, max = {8, 26, 28}, falloff = 2}
local arch = oc.segment{a = {-20, 2, 8}, b = {20, 2, 8}, radius = 13}
local rock = oc.difference(oc.union{ground, cliff}, arch)

local s = oc.layers.from_node(rock, {box = {-38, -28, -10, 38, 28, 34},
                                     cell = cell})
local st = s:stats()
print(string.format("layers_sand: %d stacks, %d layers, %d bytes", st.stacks,
                    st.layers, st.bytes))

local t0 = os.clock()
local stab = {tolerance = 0.005}
local a1, r1 = s:deposit{center = {22, -10}, radius = 12, amount = 9,
                         stabilize = stab}
local a2, r2 = s:deposit{center = {5, 14}, radius = 8, amount = 8,
                         stabilize = stab}
print(string.format("layers_sand: %.0f m^3 of sand, stabilised in %d + %d " ..
                    "passes (%.1f s CPU); sand %.1f m^3", a1 + a2,
                    r1.iterations, r2.iterations, os.clock() - t0,
                    s:volume("sand")))

local solid = s:field{materials = {"bedrock", "sand"}}
local sand = s:field{materials = {"sand"}}
local mesh = oc.polygonize(solid, {box = {-38, -28, -10, 38, 28, 34},
                                   cell = cell})
mesh:write("layers_sand.ply")
print(string.format("layers_sand: %d triangles", mesh:stats().triangles))
oc.render(solid, {camera = {eye = {70, -75, 55}, target = {2, 0, 6}, fov = 40},
                  size = {800, 450},
                  color = sand,
                  palette = {{0, {0.36, 0.30, 0.26}}, {0.3, {0.55, 0.45, 0.30}},
                             {1, {0.86, 0.74, 0.48}}}}):write("layers_sand.png")
print("layers_sand: wrote layers_sand.ply, layers_sand.png")
