-- layers_tools_spec.lua — layers:sweep (Peytavie et al. 2009, section
-- 4.2): a crack's cross-section is its profile, branches and profiles
-- per point, tunnels, and every error with its script line.
local oc = require "outcrop"
local R = require "helpers.ref"

local F = "layers_tools_spec.lua"
local function check(f, fname, ...) return R.check_error(f, F, fname, ...) end
local L = oc.layers

-- a square of half-side h with control points every h / 4 along its sides
-- (straight sides for the Catmull-Rom spline away from the corners)
local function square(h)
  local c, p = {{-h, h}, {h, h}, {h, -h}, {-h, -h}}, {}
  for k = 1, 4 do
    local a, b = c[k], c[k % 4 + 1]
    for q = 0, 7 do
      p[#p + 1] = {a[1] + (b[1] - a[1]) * q / 8, a[2] + (b[2] - a[2]) * q / 8}
    end
  end
  return p
end

local function top(s, i, j)
  local z, t = s:base(), s:base()
  for _, l in ipairs(s:get(i, j)) do
    z = z + l[2]
    if l[1] == "bedrock" then t = z end
  end
  return t
end

describe("layers:sweep", function()
  it("carves a crack with the profile's cross-section", function()
    local s = L.new{size = {41, 41}, cell = 0.5, layers = {{"bedrock", 10}}}
    local v0 = s:volume("bedrock")
    local dv, res = s:sweep{path = {{2, 10}, {18, 10}}, profiles = square(2),
                            stabilize = false}
    -- 2 m deep over 4 m (rounded corners) along 16 m, and the round ends
    assert.is_true(dv < -0.95 * 8 * 16 and dv > -8 * 20, dv)
    assert.is_true(math.abs(s:volume("bedrock") - (v0 + dv)) < 1e-6)
    assert.are.equal(0, res.iterations)
    -- stack (21, 21) is (10, 10): the floor at 8; 3 m off the axis: intact
    assert.is_true(math.abs(top(s, 21, 21) - 8) < 1e-5, top(s, 21, 21))
    assert.are.equal(10, top(s, 21, 27))
  end)

  it("takes branches, a profile per point and tunnels", function()
    local s = L.new{size = {61, 61}, cell = 0.5, layers = {{"bedrock", 10}}}
    s:sweep{path = {{{15, 15, profile = 2}, {3, 15}},
                    {{15, 15, profile = 2}, {15, 27, profile = 2}}},
            profiles = {square(1), square(3)}, stabilize = false}
    assert.is_true(math.abs(top(s, 31, 31) - 7) < 1e-5)     -- the junction
    assert.is_true(math.abs(top(s, 31, 51) - 7) < 1e-5)     -- branch 2's end
    assert.is_true(math.abs(top(s, 19, 31) - 8) < 1e-5)     -- half-way: -2
    local t = L.new{size = {21, 21}, cell = 1, layers = {{"bedrock", 10}}}
    t:sweep{path = {{0, 10, 5}, {20, 10, 5}}, profiles = square(1),
            mode = "tunnel", stabilize = false}
    local col = t:get(11, 11)
    assert.are.same({"bedrock", "air", "bedrock"},
                    {col[1][1], col[2][1], col[3][1]})
    assert.is_true(math.abs(col[2][2] - 2) < 1e-5, col[2][2])
  end)

  it("names the field and the line in errors", function()
    local s = L.new{size = {8, 8}, layers = {{"bedrock", 4}}}
    check(function() s:sweep{path = {{1, 1}}, profiles = square(1)} end,
          "layers:sweep", "'path' must hold 2 or more points")
    check(function() s:sweep{path = {{1, 1}, {2}}, profiles = square(1)} end,
          "layers:sweep", "'path[2]' must be {x, y}")
    check(function() s:sweep{path = {{1, 1}, {2, 2}}, profiles = {{0, 1}}} end,
          "layers:sweep", "'profiles[1]' must hold 3 to 1024 points")
    local bad = {{1, 1, profile = 3}, {2, 2}}
    check(function() s:sweep{path = bad, profiles = square(1)} end,
          "layers:sweep", "'profile' of path point 1 must be 1 .. 1")
    local two, sq = {{1, 1}, {2, 2}}, square(1)
    check(function() s:sweep{path = two, profiles = sq, mode = "x"} end,
          "layers:sweep", "'mode'")
    check(function() s:sweep{path = two, profiles = sq, mode = "tunnel"} end,
          "layers:sweep", "'path[1]' must be {x, y, z}")
  end)
end)
