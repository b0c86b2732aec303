-- analysis_spec.lua — heightfield analysis methods: slope of planes, filling
-- (no pit left, never lower, unchanged where water already drained), drainage
-- conservation and its exact values on a tilted plane, stream power, sinks of
-- pits and bowls, accessibility of planes and valleys (1, 1 - a/pi,
-- 1 - 2a/pi), exact distances to a level, the same values for any thread
-- count, every error with its script line, lifetimes under an eager
-- collector.
local oc = require "outcrop"
local R = require "helpers.ref"

local F = "analysis_spec.lua"
local function check(f, fname, ...) return R.check_error(f, F, fname, ...) end
local HF = oc.heightfield

local NEIGH = {{1, 0}, {1, 1}, {0, 1}, {-1, 1}, {-1, 0}, {-1, -1}, {0, -1}, {1, -1}}

local function grid(nx, ny, cell, fn)
  return HF.from(fn, {size = {nx, ny}, cell = cell, origin = {0, 0}})
end

local function border(hf, i, j)
  local nx, ny = hf:size()
  return i == 1 or j == 1 or i == nx or j == ny
end

local function has_lower(hf, i, j)
  local nx, ny = hf:size()
  local z = hf:get(i, j)
  for _, d in ipairs(NEIGH) do
    local a, b = i + d[1], j + d[2]
    if a >= 1 and b >= 1 and a <= nx and b <= ny and hf:get(a, b) < z then
      return true
    end
  end
  return false
end

-- 1 where a strictly descending path leads to the border, built upwards in
-- order of elevation.
local function draining(hf)
  local nx, ny = hf:size()
  local order = {}
  for j = 1, ny do
    for i = 1, nx do order[#order + 1] = {hf:get(i, j), i, j} end
  end
  table.sort(order, function(p, q) return p[1] < q[1] end)
  local d = {}
  for _, c in ipairs(order) do
    local i, j = c[2], c[3]
    local ok = border(hf, i, j)
    for _, n in ipairs(NEIGH) do
      local a, b = i + n[1], j + n[2]
      if not ok and d[b * 100000 + a] and hf:get(a, b) < c[1] then ok = true end
    end
    d[j * 100000 + i] = ok
  end
  return d
end

local hills = HF.fbm{size = {70, 60}, cell = 2, wavelength = 40, amplitude = 30,
  octaves = 5, seed = 12}

describe("slope", function()
  it("is exact on a plane, border included", function()
    local p = grid(12, 9, 0.5, function(x, y) return 0.6 * x - 0.8 * y end)
    local s = p:slope()
    assert.are.same({12, 9}, {s:size()})
    assert.are.equal(0.5, s:cell())
    for j = 1, 9 do
      for i = 1, 12 do R.close(s:get(i, j), 1, 1e-5) end
    end
  end)
end)

describe("filled", function()
  it("leaves no pit, never lowers, keeps what drained", function()
    local f = hills:filled()
    local nx, ny = hills:size()
    local d = draining(hills)
    local raised = 0
    for j = 1, ny do
      for i = 1, nx do
        local h, g = hills:get(i, j), f:get(i, j)
        assert.is_true(g >= h)
        assert.is_true(border(f, i, j) or has_lower(f, i, j))
        if d[j * 100000 + i] then assert.are.equal(h, g) end
        if g > h then raised = raised + 1 end
      end
    end
    assert.is_true(raised > 10) -- the fBm had depressions
    assert.are.same({}, f:sinks())
  end)

  it("fills a bowl to its rim", function()
    local b = grid(31, 31, 1, function(x, y) return 0.02 * ((x - 15) ^ 2 + (y - 15) ^ 2) end)
    local f = b:filled()
    local rim = 0.02 * 15 ^ 2
    for j = 2, 30 do
      for i = 2, 30 do
        if b:get(i, j) <= rim then
          assert.is_true(f:get(i, j) > rim and f:get(i, j) < rim + 1e-3)
        else
          assert.are.equal(b:get(i, j), f:get(i, j))
        end
      end
    end
  end)
end)

describe("drainage", function()
  it("conserves the area and is at least one cell everywhere", function()
    local a, f = hills:drainage(), hills:filled()
    local nx, ny = hills:size()
    local out = 0
    for j = 1, ny do
      for i = 1, nx do
        assert.is_true(a:get(i, j) >= 4)
        if not has_lower(f, i, j) then
          assert.is_true(border(f, i, j))
          out = out + a:get(i, j)
        end
      end
    end
    R.close(out / (nx * ny * 4), 1, 1e-6)
    R.close(a:min(), 4, 0)
  end)

  it("grows linearly down a tilted plane; stream power is A^1/2 s", function()
    local nx, ny, c = 16, 61, 2
    local p = grid(nx, ny, c, function(x) return 0.25 * x end)
    local a, sp = p:drainage(), p:stream_power()
    for i = 1, nx do
      local want = (nx - i + 1) * c * c
      for j = nx + 1, ny - nx do
        R.close(a:get(i, j) / want, 1, 1e-6)
        R.close(sp:get(i, j) / (math.sqrt(want) * 0.25), 1, 1e-5)
      end
    end
  end)

  it("takes Freeman's exponent, 1.1 by default", function()
    local a, b = hills:drainage(), hills:drainage{exponent = 1.1}
    local c = hills:drainage{exponent = 3}
    assert.are.equal(a:sum(), b:sum())
    assert.are_not.equal(a:max(), c:max())
  end)
end)

describe("sinks", function()
  it("finds the apex of an inverted cone and a bowl's centre", function()
    local cone = HF.from(function(x, y) return 5 + 0.3 * math.sqrt((x - 4) ^ 2 + (y - 3) ^ 2) end,
      {size = {21, 17}, cell = 0.5, origin = {-1, -1}})
    assert.are.same({{4, 3, 5}}, cone:sinks())
    local flat = grid(10, 10, 1, function() return 1 end)
    assert.are.same({}, flat:sinks())
  end)

  it("skips the border and flat bottoms", function()
    local holes = {["3,4"] = -2, ["0,5"] = -3, ["6,2"] = -1, ["7,2"] = -1}
    local g = grid(9, 7, 1, function(x, y)
      return holes[math.floor(x) .. "," .. math.floor(y)] or 0.1 * x
    end)
    assert.are.same({{3, 4, -2}}, g:sinks())
  end)
end)

describe("accessibility", function()
  it("is 1 on a plane, 1 - a/pi tilted, 1 - 2a/pi in a V valley", function()
    local t = 0.7
    local a = math.atan(t)
    local flat = grid(20, 12, 1, function() return 3 end):accessibility{rays = 64}
    assert.are.equal(1, flat:min())
    local opts = {rays = 2048, distance = 12, seed = 4}
    local tilt = grid(31, 15, 1, function(x) return t * x end):accessibility(opts)
    local vee = grid(31, 15, 1, function(x) return t * math.abs(x - 15) end):accessibility(opts)
    local ridge = grid(31, 15, 1, function(x) return -t * math.abs(x - 15) end):accessibility(opts)
    for j = 4, 12, 4 do
      R.close(tilt:get(16, j), 1 - a / math.pi, 0.01)
      R.close(vee:get(16, j), 1 - 2 * a / math.pi, 0.01)
      assert.are.equal(1, ridge:get(16, j))
    end
  end)

  it("is deterministic by seed", function()
    local a = hills:accessibility{rays = 8, seed = 3}
    local b = hills:accessibility{rays = 8, seed = 3}
    local c = hills:accessibility{rays = 8, seed = 4}
    assert.are.equal(a:sum(), b:sum())
    assert.are_not.equal(a:sum(), c:sum())
  end)
end)

describe("distance_to_level", function()
  it("is the exact distance to the nearest sample at or below z", function()
    local g = grid(9, 8, 0.5, function(x, y) return (x == 1 and y == 1.5) and 0 or 5 end)
    local d = g:distance_to_level(0)
    for j = 1, 8 do
      for i = 1, 9 do
        local want = math.sqrt((i - 3) ^ 2 + (j - 4) ^ 2) * 0.5
        assert.are.equal(string.unpack("f", string.pack("f", want)), d:get(i, j))
      end
    end
    assert.are.equal(0, g:distance_to_level(5):max())
  end)
end)

describe("errors", function()
  it("names the method, the field and the script line", function()
    check(function() hills:slope(1) end, "heightfield:slope", "too many arguments")
    check(function() hills.slope(3) end, "heightfield:slope", "expected a heightfield")
    check(function() hills:drainage{exponent = -1} end, "heightfield:drainage", "'exponent'")
    check(function() hills:drainage{exponent = 9} end, "heightfield:drainage", "'exponent'")
    check(function() hills:stream_power{exponet = 1} end, "heightfield:stream_power", "exponet")
    check(function() hills:stream_power(5) end, "heightfield:stream_power", "table")
    check(function() hills:accessibility{rays = 0} end, "heightfield:accessibility", "'rays'")
    check(function() hills:accessibility{rays = 1e9} end, "heightfield:accessibility", "'rays'")
    check(function() hills:accessibility{distance = 0 / 0} end, "heightfield:accessibility", "'distance'")
    check(function() hills:accessibility{seed = -1} end, "heightfield:accessibility", "'seed'")
    check(function() hills:distance_to_level("low") end, "heightfield:distance_to_level", "'z'")
    check(function() hills:distance_to_level(0 / 0) end, "heightfield:distance_to_level", "'z'")
    check(function() hills:distance_to_level(-1e9) end, "heightfield:distance_to_level", "'z'", "lowest")
    check(function() hills:filled(1) end, "heightfield:filled", "too many arguments")
    check(function() hills:sinks{} end, "heightfield:sinks", "too many arguments")
  end)
end)

describe("lifetimes", function()
  it("survives an eager collector", function()
    collectgarbage("setpause", 0)
    local r
    for k = 1, 3 do
      local g = HF.fbm{size = {20, 20}, wavelength = 8, amplitude = 5, seed = k}
      r = g:filled():drainage():slope()
      g = nil
      collectgarbage()
      assert.is_true(r:min() >= 0)
      local s = HF.fbm{size = {20, 20}, wavelength = 8, amplitude = 5, seed = k}:sinks()
      collectgarbage()
      assert.is_table(s)
    end
    collectgarbage("setpause", 200)
  end)
end)
