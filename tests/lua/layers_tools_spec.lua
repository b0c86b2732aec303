-- layers_tools_spec.lua — layers:sweep (Peytavie et al. 2009, section
-- 4.2): a crack's cross-section is its profile, branches and profiles
-- per point, tunnels, and every error with its script line; texturing by
-- material (section 6): a render with color = stacks:colors() against a
-- golden image (tests/fixtures/render/layers_texture.lua, the linear
-- R, G, B of 32 x 24 pixels; OUTCROP_REGEN_GOLDEN=1 rewrites it).
local oc = require "outcrop"
local R = require "helpers.ref"

local F = "layers_tools_spec.lua"
local function check(f, fname, ...) return R.check_error(f, F, fname, ...) end
local L = oc.layers
local GOLDEN = "../fixtures/render/layers_texture.lua"
local regen = os.getenv("OUTCROP_REGEN_GOLDEN") == "1"

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

describe("texturing by material", function()
  it("renders stacks:colors() as the golden image", function()
    -- bedrock 4 m, sand 1.5 m on one half, a rock bank on a corner
    local s = L.new{size = {16, 16}, layers = {{"bedrock", 4}}}
    for j = 1, 16 do
      for i = 1, 16 do
        if i <= 8 then s:set(i, j, {{"bedrock", 4}, {"sand", 1.5}}) end
        if i > 11 and j > 11 then s:set(i, j, {{"bedrock", 4}, {"rocks", 2}}) end
      end
    end
    local c = s:colors()
    assert.are.equal(3, #c.blend) -- bedrock, rocks, sand: those present
    local img = oc.render(s:field(), {size = {32, 24}, aov = false,
      camera = {eye = {30, -18, 22}, target = {8, 8, 3}, fov = 45},
      color = c})
    local now = {}
    for j = 1, 24 do
      for i = 1, 32 do
        local r, g, b = img:get(i, j)
        now[#now + 1] = string.format("%.4f,%.4f,%.4f", r, g, b)
      end
    end
    if regen then
      local f = assert(io.open(GOLDEN, "w"))
      f:write("-- layers_tools_spec.lua's golden render (linear R, G, B)\n",
              "return {", table.concat(now, ","), "}\n")
      f:close()
      print("\nwrote " .. GOLDEN)
      return
    end
    local want = dofile(GOLDEN)
    assert.are.equal(32 * 24 * 3, #want)
    local sum, max, k = 0, 0, 0
    for _, px in ipairs(now) do
      for v in px:gmatch("[^,]+") do
        k = k + 1
        local d = math.abs(tonumber(v) - want[k])
        sum, max = sum + d, math.max(max, d)
      end
    end
    -- rendering is deterministic: beyond the 4 digits kept, a change
    assert.is_true(sum / k <= 2e-3, "mean difference " .. sum / k)
    assert.is_true(max <= 0.05, "largest difference " .. max)
  end)
  -- the weights of a blend at a point, and their shares
  local function shares(c, x, y, z)
    local w, sum, r = {}, 0, {}
    for k, e in ipairs(c.blend) do
      w[k] = e[1]:eval(x, y, z)
      sum = sum + w[k]
    end
    for k = 1, #w do r[k] = w[k] / sum end
    return r, w
  end
  it("colours a cover thinner than sigma by the visible ratio", function()
    -- bedrock 4 m under 0.25 m of sand, sigma 1 m: the box around a point
    -- of the surface holds 1 m^3 of sand and 3 of bedrock
    local s = L.new{size = {8, 8}, layers = {{"bedrock", 4}, {"sand", 0.25}}}
    local vis, vol = s:colors(), s:colors{ratio = "volume"}
    local r, w = shares(vis, 4.2, 3.7, 4.25) -- blend: bedrock, sand
    -- S_sand = 1 (the top at the point), plus 1e-6 V / V_Omega
    assert.is_true(math.abs(w[2] - (1 + 1e-6 / 8)) < 1e-12)
    assert.is_true(math.abs(w[1] - 1e-6 * 3 / 8) < 1e-15)
    assert.is_true(r[2] > 1 - 1e-6, "visible sand " .. r[2])
    -- half a sigma above, the tent halves the sand's weight
    local _, wh = shares(vis, 4.2, 3.7, 4.75)
    assert.is_true(math.abs(wh[2] - (0.5 + 1e-6 / 8)) < 1e-12)
    -- the volume ratio sees the bedrock under the cover: 25 % sand
    local rv = shares(vol, 4.2, 3.7, 4.25)
    assert.is_true(math.abs(rv[2] - 0.25) < 1e-12, "volume sand " .. rv[2])
    -- far from the surface nothing is visible: the volume ratio decides
    local rd = shares(vis, 4.2, 3.7, 2.5)
    assert.is_true(math.abs(rd[1] - 1) < 1e-12)
  end)
  it("splits a vertical boundary between two materials 50/50", function()
    -- sand in the stacks i <= 4 (x < 3.5), bedrock beyond, both 4 m high
    local s = L.new{size = {8, 8}, layers = {{"bedrock", 4}}}
    for j = 1, 8 do
      for i = 1, 4 do s:set(i, j, {{"sand", 4}}) end
    end
    local c = s:colors()
    local r = shares(c, 3.5, 3.7, 4) -- blend: bedrock, sand
    assert.is_true(math.abs(r[1] - 0.5) < 1e-12 and math.abs(r[2] - 0.5) < 1e-12)
    -- half a sigma into the sand: the footprint [2.5, 4.5] is 3/4 sand
    r = shares(c, 3, 3.7, 4.2)
    assert.is_true(math.abs(r[2] - 0.75) < 1e-12, "sand " .. r[2])
  end)
  it("names the field and the line in errors", function()
    local s = L.new{size = {4, 4}, layers = {{"bedrock", 2}}}
    local f = s:field()
    check(function() oc.render(f, {color = {blend = {{5, {1, 1, 1}}}}}) end,
          "outcrop.render", "'color.blend[1]' must be {node, {r, g, b}}")
    check(function() oc.render(f, {color = {blend = {}}}) end,
          "outcrop.render", "'color.blend' must hold 1 to 16 pairs")
    check(function() s:colors{sand = {2, 0, 0}} end, "layers:colors",
          "'sand' must be {r, g, b} in [0, 1]")
    check(function() s:colors{sigma = 0} end, "layers:colors", "'sigma'")
    check(function() s:colors{ratio = "area"} end, "layers:colors", "'ratio'")
    check(function() L.new{size = {2, 2}}:colors() end, "layers:colors",
          "the stacks hold no material")
  end)
end)
