-- layers_spec.lua — outcrop.layers (material stacks, Peytavie et al. 2009):
-- the canonical form, volumes and stats, the convolution field against
-- its formula, from_node reproducing a node's surface within a cell,
-- stabilisation and deposit conserving volume and leaving every slope
-- under the angle of repose, the same bytes on one and two threads, and
-- every error with its script line.
local oc = require "outcrop"
local R = require "helpers.ref"

local F = "layers_spec.lua"
local function check(f, fname, ...) return R.check_error(f, F, fname, ...) end
local L = oc.layers
local T = 0.5

describe("outcrop.layers", function()
  it("keeps stacks canonical: merged, sorted between bedrock", function()
    local s = L.new{size = {3, 2}, cell = 2, base = -1}
    s:set(2, 1, {{"sand", 1}, {"bedrock", 2}, {"air", 1}, {"water", 0.5},
                 {"sand", 0.25}, {"rocks", 1}, {"sand", 0.25}, {"bedrock", 1},
                 {"bedrock", 3}, {"air", 2}})
    local got = s:get(2, 1)
    local want = {{"sand", 1}, {"bedrock", 2}, {"sand", 0.5}, {"rocks", 1},
                  {"water", 0.5}, {"air", 1}, {"bedrock", 4}}
    assert.are.same(want, got)
    assert.are.same({}, s:get(1, 1))
    assert.are.equal(0.5 * 4 + 1 * 4, s:volume("sand"))
    assert.are.equal(6 * 4, s:volume("bedrock"))
    local st = s:stats()
    assert.are.equal(6, st.stacks)
    assert.are.equal(7, st.layers)
    assert.is_true(st.bytes >= 7 * 4 * 4 and st.bytes < 200, st.bytes)
    -- the top of sand: -1 + 1 + 2 + 0.5 = 2.5; none: the base
    local hf = s:heightfield("sand")
    assert.are.equal(2.5, hf:get(2, 1))
    assert.are.equal(-1, hf:get(1, 1))
    assert.are.equal(9, s:heightfield("bedrock"):get(2, 1))
  end)

  it("converts a heightfield: bedrock under it, sand on it", function()
    local hf = oc.heightfield.from(function(x, y) return 10 + x + 0.5 * y end,
                                   {size = {8, 6}, cell = 1})
    local s = L.from_heightfield(hf, {base = 0, sand = 0.25})
    local sum = 0
    for j = 1, 6 do for i = 1, 8 do sum = sum + hf:get(i, j) end end
    assert.is_true(math.abs(s:volume("bedrock") - sum) < 1e-9)
    assert.are.equal(48 * 0.25, s:volume("sand"))
    assert.are.equal(hf:get(3, 4) + 0.25, s:heightfield("sand"):get(3, 4))
  end)

  it("makes the convolution field 2T V_M / V_Omega", function()
    local s = L.new{size = {9, 9}, cell = 1, layers = {{"bedrock", 10}, {"sand", 2}}}
    local sand = s:field{materials = {"sand"}, sigma = 0.5}
    local both = s:field{materials = {"bedrock", "sand"}}
    -- inside the grid, with a cube of half-side sigma: f linear in z
    for z = 8.05, 14, 0.3 do
      local hs = math.max(0, math.min(12, z + 0.5) - math.max(10, z - 0.5))
      assert.is_true(math.abs(sand:eval(4.2, 3.7, z) - 2 * T * hs) < 1e-12)
      local hb = math.max(0, math.min(12, z + 1) - math.max(0, z - 1))
      assert.is_true(math.abs(both:eval(4.2, 3.7, z) - 2 * T * hb / 2) < 1e-12)
    end
    assert.is_true(math.abs(both:eval(4, 4, 12) - T) < 1e-12)
    assert.is_true(math.abs(both:lipschitz() - math.sqrt(3) * T) < 1e-6)
    -- gradient where defined: -T / sigma through the top
    local g = R.numgrad(both, {4.3, 4.1, 11.6}, 1e-6)
    assert.is_true(math.abs(g[3] + T) < 1e-6 and math.abs(g[1]) < 1e-6)
    -- past the grid's side the cube is partly empty
    assert.are.equal(0, both:eval(12, 4, 5))
    assert.is_true(math.abs(both:eval(8.5, 4, 5) - T) < 1e-12)
  end)

  it("reproduces a node's surface within a cell (caves as air)", function()
    local ball = oc.sphere{center = {0, 0, 0}, radius = 5, falloff = 2}
    local rs = 5 + 0.45420201894740647 * 2
    local s = L.from_node(ball, {box = {-8, -8, -8, 8, 8, 8}, cell = 0.5})
    local nx, ny = s:size()
    assert.are.equal(33, nx)
    assert.are.equal(33, ny)
    local mid = s:get(17, 17)
    assert.are.equal(2, #mid) -- air below the ball, then the ball
    assert.are.equal("air", mid[1][1])
    assert.is_true(math.abs(mid[2][2] - 2 * rs) < 1e-5)
    local f = s:field{materials = {"bedrock"}}
    for k = 1, 100 do
      local th, ph = k * 2.39996, math.acos(1 - 2 * (k - 0.5) / 100)
      local d = {math.sin(ph) * math.cos(th), math.sin(ph) * math.sin(th), math.cos(ph)}
      local a, b = rs - 1, rs + 1
      assert.is_true(f:eval(a * d[1], a * d[2], a * d[3]) > T)
      assert.is_true(f:eval(b * d[1], b * d[2], b * d[3]) < T)
      for _ = 1, 40 do
        local c = (a + b) / 2
        if f:eval(c * d[1], c * d[2], c * d[3]) > T then a = c else b = c end
      end
      assert.is_true(math.abs(a - rs) <= 0.5, a)
    end
    local m = oc.polygonize(f, {cell = 0.5})
    assert.is_true(m:stats().triangles > 1000)
  end)

  it("stabilises sand to rest, conserving its volume", function()
    local s = L.new{size = {30, 30}, cell = 1, layers = {{"bedrock", 5}}}
    for j = 1, 30 do
      for i = 1, 30 do
        local r = math.sqrt((i - 15) ^ 2 + (j - 12) ^ 2)
        s:set(i, j, {{"bedrock", 5}, {"sand", math.max(0, 8 - r)}})
      end
    end
    local v0 = s:volume("sand")
    local r = s:stabilize{angle = {sand = 30}}
    assert.is_true(r.converged and r.iterations > 10 and r.moved > 0)
    assert.is_true(math.abs(s:volume("sand") - v0) < 1e-6 * v0)
    local h = s:heightfield("sand")
    local ta = math.tan(math.rad(30))
    for j = 2, 29 do
      for i = 2, 29 do
        if h:get(i, j) > 5 then
          for dj = -1, 1 do
            for di = -1, 1 do
              local lim = ((di ~= 0 and dj ~= 0) and math.sqrt(2) or 1) * ta
              local nb = math.max(h:get(i + di, j + dj), 5)
              assert.is_true(h:get(i, j) - nb <= lim + 0.01)
            end
          end
        end
      end
    end
    -- deposit: the volume added is there afterwards
    local added, r2 = s:deposit{center = {20, 20}, radius = 6, amount = 4}
    assert.is_true(added > 0 and r2.converged)
    assert.is_true(math.abs(s:volume("sand") - v0 - added) < 1e-6 * (v0 + added))
    local ar = s:deposit{center = {10, 10}, radius = 3, amount = 2, material = "rocks",
                         stabilize = {angle = {rocks = 40}}}
    assert.is_true(math.abs(s:volume("rocks") - ar) < 1e-6 * ar)
  end)

  it("erodes bedrock into sand and rocks, conserving volume", function()
    local s = L.new{size = {8, 8}, layers = {{"bedrock", 4}, {"air", 2}, {"bedrock", 1}}}
    local v, r = s:erode{region = {2, 2, 3, 4}, mode = "collapse", ratio = 0.25,
                         stabilize = false}
    assert.are.equal(6, v)
    assert.are.same({{"bedrock", 4}, {"sand", 0.25}, {"rocks", 0.75}}, s:get(3, 4))
    assert.are.equal(3, #s:get(3, 5))
    local total = function()
      return s:volume("bedrock") + s:volume("sand") + s:volume("rocks")
    end
    local t0 = total()
    v, r = s:erode{region = {0, 0, 7, 7}, depth = 0.5}
    assert.are.equal(64 * 0.5 - 6 * 0.5 + 6 * 0.5, v)
    assert.is_true(math.abs(total() - t0) < 1e-6 * t0 and r.converged)
    check(function() s:erode{region = {0, 0, 1, 1}, ratio = 2} end, "layers:erode", "'ratio'")
    check(function() s:erode{region = {0, 0, 1, 1}, mode = "melt"} end, "layers:erode", "'mode'")
    check(function() s:erode{} end, "layers:erode", "'region'")
  end)

  it("sculpts bedrock: add raises it, carve removes it", function()
    local s = L.new{size = {20, 20}, cell = 0.5, layers = {{"bedrock", 10}, {"sand", 0.2}}}
    local v0 = s:volume("bedrock")
    local dv = s:sculpt{center = {5, 5, 10}, radius = 2.5, strength = 2}
    assert.is_true(dv > 1)
    assert.is_true(math.abs(s:volume("bedrock") - v0 - dv) < 1e-9)
    assert.is_true(s:heightfield("bedrock"):get(11, 11) > 10.5)
    assert.are.equal(10, s:heightfield("bedrock"):get(1, 1))
    -- the sand it lifted stays on top, and no sand is lost
    assert.is_true(math.abs(s:volume("sand") - 400 * 0.2 * 0.25) < 1e-4)
    local dc = s:sculpt{center = {5, 5, 9}, radius = 2.5, mode = "carve", stabilize = false}
    assert.is_true(dc < -1)
    check(function() s:sculpt{center = {0, 0, 0}, radius = -1} end, "layers:sculpt", "'radius'")
    check(function() s:sculpt{center = {0, 0, 0}, radius = 1, mode = "smear"} end,
      "layers:sculpt", "'mode'")
    check(function() s:sculpt{radius = 1} end, "layers:sculpt", "'center'")
  end)

  it("is the same to the byte on one and two threads", function()
    local function child(threads)
      return R.child_output(threads, "local oc = require \"outcrop\" " ..
        "local s = oc.layers.new{size = {60, 50}, layers = {{\"bedrock\", 3}}} " ..
        "s:deposit{center = {20, 20}, radius = 12, amount = 9} " ..
        "s:deposit{center = {30, 25}, radius = 8, amount = 5, material = \"rocks\"} " ..
        "local t = {} for j = 1, 50 do for i = 1, 60 do " ..
        "for _, l in ipairs(s:get(i, j)) do " ..
        "t[#t + 1] = l[1] .. string.pack(\"d\", l[2]) end end end " ..
        "io.write(table.concat(t))")
    end
    local one, two = child(1), child(2)
    assert.is_true(#one > 3000 * 8)
    assert.is_true(one == two)
  end)

  it("refuses bad fields, naming them and the line", function()
    local s = L.new{size = {4, 4}, layers = {{"bedrock", 1}}}
    check(function() s:set(1, 1, {{"bedrock", -1}}) end, "layers:set", "'layers[1]' thickness")
    check(function() s:set(1, 1, {{"lava", 1}}) end, "layers:set", "'layers[1]' material", "'lava'")
    check(function() s:set(5, 1, {}) end, "layers:set", "i must be")
    check(function() s:field{sigma = 0} end, "layers:field", "'sigma'")
    check(function() s:field{sigma = -2} end, "layers:field", "'sigma'")
    check(function() s:field{materials = {"air"}} end, "layers:field", "'materials[1]'")
    check(function() s:field{materials = {"mud"}} end, "layers:field", "'materials[1]'")
    check(function() s:volume("mud") end, "layers:volume", "material")
    check(function() s:stabilize{angle = {sand = 95}} end, "layers:stabilize", "'angle.sand'")
    check(function() s:stabilize{rate = 2} end, "layers:stabilize", "'rate'")
    check(function() s:deposit{center = {1, 1}, radius = -1, amount = 1} end,
      "layers:deposit", "'radius'")
    check(function() s:deposit{center = {1, 1}, radius = 1, amount = 1, material = "bedrock"} end,
      "layers:deposit", "'material'")
    check(function() L.new{size = {0, 3}} end, "outcrop.layers.new", "'size'")
    check(function() L.new{size = {3, 3}, cell = -1} end, "outcrop.layers.new", "'cell'")
    check(function() L.new{size = {3, 3}, layers = {{"sand", -1}}} end,
      "outcrop.layers.new", "'layers[1]' thickness")
    check(function() L.from_node(oc.sphere{center = {0, 0, 0}, radius = 1}, {cell = 1}) end,
      "outcrop.layers.from_node", "'box'")
    check(function() L.from_node(oc.sphere{center = {0, 0, 0}, radius = 1},
      {box = {-1, -1, -1, 1, 1, 1}, cell = 1, material = "air"}) end,
      "outcrop.layers.from_node", "'material'")
    check(function() L.from_heightfield(oc.heightfield.from(function() return 0 end,
      {size = {3, 3}}), {sand = -1}) end, "outcrop.layers.from_heightfield", "'sand'")
  end)
end)
