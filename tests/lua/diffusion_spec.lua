-- diffusion_spec.lua — outcrop.feature_curve and outcrop.diffusion
-- (Hnaidi et al. 2010): attributes interpolated along a curve, strict
-- elevations met, the inspection grids, a slope measured on a ridge,
-- the same terrain from the same seed and another from another seed,
-- and every error naming its field and the script line.
local oc = require "outcrop"
local R = require "helpers.ref"

local F = "diffusion_spec.lua"
local function check(f, fname, ...) return R.check_error(f, F, fname, ...) end

local function ridge(theta)
  return oc.feature_curve{
    points = {{-50, 32}, {114, 32}},
    constraints = {
      {u = 0, height = 40, radius = 1,
       slope = {left = theta, right = theta, extent = {20, 20}},
       noise = {amplitude = 2, roughness = 0.5}},
      {u = 1, height = 40, radius = 1,
       slope = {left = theta, right = theta, extent = {20, 20}},
       noise = {amplitude = 2, roughness = 0.5}},
    }}
end

describe("outcrop.feature_curve", function()
  it("interpolates h by a natural spline and the rest linearly", function()
    local c = oc.feature_curve{
      points = {{0, 0}, {30, 0}, {70, 0}, {100, 0}}, bezier = true,
      constraints = {{u = 0, height = 0, radius = 2},
                     {u = 0.5, height = 10},
                     {u = 1, height = 0, radius = 4}}}
    R.close(c:length(), 100, 1e-9)
    local s = c:sample(0.5)
    R.close(s.height, 10, 1e-12)
    R.close(s.radius, 3, 1e-12)
    R.close(s.x, 50, 1e-9)
    -- natural spline through (0, 0), (0.5, 10), (1, 0): m1 = -120, so
    -- h(0.25) = 5 + (0.25^3 - 0.25) * 0.5 * -120 / 6 ... = 6.875
    R.close(c:sample(0.25).height, 6.875, 1e-9)
    assert.is_nil(s.left)
    assert.is_true(tostring(c):find("outcrop.feature_curve", 1, true) ~= nil)
  end)

  it("saves to a few bytes and loads back", function()
    local c = ridge(30)
    local s = c:save()
    assert.is_true(#s < 64)
    local d = oc.feature_curve_load(s)
    assert.are.equal(s, d:save())
    R.close(d:sample(0.5).height, 40, 1e-12)
    R.close(d:sample(0.5).left, 30, 1 / 64)
    check(function() oc.feature_curve_load("nope") end,
          "outcrop.feature_curve_load", "not a feature curve encoding")
    check(function() oc.feature_curve_load(s:sub(1, -2)) end,
          "outcrop.feature_curve_load", "truncated")
  end)

  it("names the field of every bad input", function()
    local fc = "outcrop.feature_curve"
    local pts = {{0, 0}, {10, 0}}
    check(function() oc.feature_curve{points = pts,
            constraints = {{u = 0, height = 1}}} end, fc, "'constraints'")
    check(function() oc.feature_curve{points = pts,
            constraints = {{u = 0, height = 1}, {u = 2, height = 1}}} end,
          fc, "'constraints[2].u'")
    check(function() oc.feature_curve{points = pts,
            constraints = {{u = 0, height = 0 / 0}, {u = 1}}} end,
          fc, "'constraints[1].height'")
    check(function() oc.feature_curve{points = pts,
            constraints = {{u = 0, slope = {left = 10, extent = {1, 1}}},
                           {u = 1}}} end,
          fc, "'constraints[1].slope.right'")
    check(function() oc.feature_curve{points = pts,
            constraints = {{u = 0, noise = {amplitude = 1, roughness = 3}},
                           {u = 1}}} end,
          fc, "'constraints[1].noise.roughness'")
    check(function() oc.feature_curve{points = pts,
            constraints = {{u = 0, heigth = 1}, {u = 1}}} end,
          fc, "constraints[1].heigth")
    check(function() oc.feature_curve{points = pts, bezier = true,
            constraints = {{u = 0}, {u = 1}}} end, fc, "'points'")
    check(function() oc.feature_curve{points = {{0, 0}},
            constraints = {{u = 0}, {u = 1}}} end, fc, "'points'")
  end)
end)

describe("outcrop.diffusion", function()
  it("meets the strict elevation and returns the inspection grids", function()
    local hf, maps = oc.diffusion{size = {64, 64}, curves = {ridge(30)},
                                  seed = 3, noise = {wavelength = 16}}
    assert.are.equal(64, (hf:size()))
    -- sample (33, 33) lies on the ridge at y = 32
    R.close(maps.smooth:get(33, 33), 40, 1e-5)
    R.close(hf:get(33, 33), 40 + maps.detail:get(33, 33), 1e-4)
    R.close(maps.amplitude:get(33, 33), 2, 1e-6)
    assert.is_true(maps.strict > 0 and maps.slope > 0)
    assert.is_true(maps.levels >= 4)
    -- the detail stays within 4 A... at most 1.875 A + (R = 0.5) terms
    for _, g in ipairs{maps.detail} do
      assert.is_true(g:max() <= 4 * 2 and g:min() >= -4 * 2)
    end
    -- the flank falls: tan 30 at the inner edge, fading over 20 m
    local drop = maps.smooth:get(33, 33) - maps.smooth:get(33, 43)
    assert.is_true(drop > 2 and drop < 9 * math.tan(math.pi / 6) + 0.5)
  end)

  it("is the same for the same seed and differs for another", function()
    local a = oc.diffusion{size = {48, 48}, curves = {ridge(20)}, seed = 5}
    local b = oc.diffusion{size = {48, 48}, curves = {ridge(20)}, seed = 5}
    local c = oc.diffusion{size = {48, 48}, curves = {ridge(20)}, seed = 6}
    local same, differ = true, false
    for j = 1, 48 do
      for i = 1, 48 do
        same = same and a:get(i, j) == b:get(i, j)
        differ = differ or a:get(i, j) ~= c:get(i, j)
      end
    end
    assert.is_true(same and differ)
  end)

  it("converges on request, with the residuals of its cycles", function()
    local _, maps = oc.diffusion{size = {64, 64}, curves = {ridge(30)},
                                 converged = true}
    assert.is_true(maps.cycles >= 1)
    -- the default tolerance 1e-4 of the strict elevations' scale (40 m)
    assert.is_true(maps.residuals[maps.cycles + 1] <= 1e-4 * 40)
    assert.is_true(maps.residuals[maps.cycles] > 1e-4 * 40)
    local _, paper = oc.diffusion{size = {64, 64}, curves = {ridge(30)},
                                  scheme = "paper"}
    assert.are.equal(0, paper.cycles)
  end)

  it("keeps its curves while Lua code runs in the call", function()
    local curves = {ridge(30)}
    local opts = setmetatable({size = {64, 64}, curves = curves}, {
      __index = function(_, k)
        if k == "seed" then
          curves[1] = nil -- the script's last reference
          collectgarbage()
          collectgarbage()
        end
      end})
    local hf, maps = oc.diffusion(opts)
    assert.is_nil(curves[1])
    R.close(maps.smooth:get(33, 33), 40, 1e-5)
    assert.is_true(hf:max() > 30)
  end)

  it("names the field of every bad input", function()
    local fn = "outcrop.diffusion"
    local r = ridge(10)
    check(function() oc.diffusion{curves = {r}} end, fn, "'size'")
    check(function() oc.diffusion{size = {8, 8}, curves = {}} end, fn,
          "'curves'")
    check(function() oc.diffusion{size = {8, 8}, curves = {r, 3}} end, fn,
          "'curves[2]'")
    check(function() oc.diffusion{size = {8, 8}, curves = {r},
                                  scheme = "fast"} end, fn, "'scheme'")
    check(function() oc.diffusion{size = {8, 8}, curves = {r},
                                  converged = 2} end, fn, "'converged'")
    check(function() oc.diffusion{size = {8, 8}, curves = {r},
                                  noise = {ratio = 1}} end, fn,
          "'noise.ratio'")
    check(function() oc.diffusion{size = {8, 8}, curves = {r},
                                  noise = {octaves = 0}} end, fn,
          "'noise.octaves'")
    check(function() oc.diffusion{size = {8, 8}, curves = {r}, cell = -1} end,
          fn, "'cell'")
    local crack = oc.feature_curve{points = {{0, 0}, {8, 8}},
      constraints = {{u = 0, slope = {left = -30, right = -30,
                                      extent = {2, 2}}}, {u = 1}}}
    check(function() oc.diffusion{size = {8, 8}, curves = {crack}} end, fn,
          "'curves'", "no strict elevation")
    local far = oc.feature_curve{points = {{100, 100}, {120, 100}},
      constraints = {{u = 0, height = 1}, {u = 1, height = 1}}}
    check(function() oc.diffusion{size = {8, 8}, curves = {far}} end, fn,
          "'curves'", "inside the grid")
  end)
end)
