/* The OpenCL backend's default device choice, against a fake loader table
 * (no OpenCL driver needed): a usable GPU before a CPU device, a CPU device
 * when the GPU has no float64, a named device as named. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#ifdef MESHFMM_TEST_HAVE_CL
#define MESHFMM_HAVE_OPENCL 1
#define CL_TARGET_OPENCL_VERSION 120
#include "matrix/opencl/device.h"

typedef struct fake_device {
    const char *name;
    cl_device_type type;
    int fp64;
} fake_device;

static const fake_device *devices; /* the table a test installs */
static cl_uint n_devices;
static int platform_tag;

static cl_int fake_platforms(cl_uint n, cl_platform_id *plats, cl_uint *np)
{
    if (np)
        *np = 1;
    if (plats && n > 0)
        plats[0] = (cl_platform_id)(void *)&platform_tag;
    return CL_SUCCESS;
}

static cl_int fake_device_ids(cl_platform_id p, cl_device_type type, cl_uint n,
                              cl_device_id *out, cl_uint *k)
{
    (void)p;
    (void)type;
    cl_uint m = n_devices < n ? n_devices : n;
    for (cl_uint i = 0; i < m; i++)
        out[i] = (cl_device_id)(void *)&devices[i];
    if (k)
        *k = m;
    return CL_SUCCESS;
}

static cl_int fake_device_info(cl_device_id d, cl_device_info what, size_t size, void *value,
                               size_t *ret)
{
    const fake_device *dev = (const fake_device *)(void *)d;
    (void)ret;
    switch (what) {
    case CL_DEVICE_TYPE:
        assert_true(size >= sizeof(cl_device_type));
        *(cl_device_type *)value = dev->type;
        return CL_SUCCESS;
    case CL_DEVICE_NAME:
        assert_true(size > strlen(dev->name));
        strcpy(value, dev->name);
        return CL_SUCCESS;
    case CL_DEVICE_DOUBLE_FP_CONFIG:
        *(cl_device_fp_config *)value = dev->fp64 ? CL_FP_FMA | CL_FP_ROUND_TO_NEAREST : 0;
        return CL_SUCCESS;
    case CL_DEVICE_COMPILER_AVAILABLE:
        *(cl_bool *)value = CL_TRUE;
        return CL_SUCCESS;
    case CL_DEVICE_GLOBAL_MEM_SIZE:
    case CL_DEVICE_MAX_MEM_ALLOC_SIZE:
        *(cl_ulong *)value = (cl_ulong)1 << 30;
        return CL_SUCCESS;
    case CL_DEVICE_MAX_COMPUTE_UNITS:
        *(cl_uint *)value = 8;
        return CL_SUCCESS;
    default:
        return CL_INVALID_VALUE;
    }
}

/* Selects with the given table; returns the status, the pick in *cl. */
static mfmm_status select_from(const fake_device *table, cl_uint n, const char *want, ocl *cl,
                               mfmm_error *err)
{
    static mfmm_cl_api api;
    memset(&api, 0, sizeof api);
    api.clGetPlatformIDs = fake_platforms;
    api.clGetDeviceIDs = fake_device_ids;
    api.clGetDeviceInfo = fake_device_info;
    devices = table;
    n_devices = n;
    memset(cl, 0, sizeof *cl);
    cl->api = &api;
    unsetenv("MESHFMM_OPENCL_DEVICE");
    return mfmm_cl_select_device(cl, want, err);
}

static void test_gpu_before_cpu(void **state)
{
    (void)state;
    const fake_device table[] = {{"pthread-cpu", CL_DEVICE_TYPE_CPU, 1},
                                 {"Some GPU", CL_DEVICE_TYPE_GPU, 1}};
    ocl cl;
    mfmm_error err;
    assert_int_equal(select_from(table, 2, NULL, &cl, &err), MFMM_OK);
    assert_ptr_equal(cl.device, (cl_device_id)(void *)&table[1]);
    assert_string_equal(cl.name, "Some GPU");
    assert_int_equal(cl.cpu, 0);
    assert_int_equal(cl.named, 0);
}

static void test_cpu_when_gpu_lacks_float64(void **state)
{
    (void)state;
    const fake_device table[] = {{"Small GPU", CL_DEVICE_TYPE_GPU, 0},
                                 {"pthread-cpu", CL_DEVICE_TYPE_CPU, 1}};
    ocl cl;
    mfmm_error err;
    assert_int_equal(select_from(table, 2, NULL, &cl, &err), MFMM_OK);
    assert_ptr_equal(cl.device, (cl_device_id)(void *)&table[1]);
    assert_int_equal(cl.cpu, 1);
}

static void test_no_usable_device_is_refused(void **state)
{
    (void)state;
    const fake_device table[] = {{"Small GPU", CL_DEVICE_TYPE_GPU, 0}};
    ocl cl;
    mfmm_error err;
    assert_int_equal(select_from(table, 1, NULL, &cl, &err), MFMM_ERR_NO_OPENCL);
    assert_non_null(strstr(err.message, "float64"));
}

static void test_named_device_wins(void **state)
{
    (void)state;
    const fake_device table[] = {{"Some GPU", CL_DEVICE_TYPE_GPU, 1},
                                 {"pthread-cpu", CL_DEVICE_TYPE_CPU, 1}};
    ocl cl;
    mfmm_error err;
    assert_int_equal(select_from(table, 2, "PTHREAD", &cl, &err), MFMM_OK);
    assert_ptr_equal(cl.device, (cl_device_id)(void *)&table[1]);
    assert_int_equal(cl.cpu, 1);
    assert_int_equal(cl.named, 1);
    assert_int_equal(select_from(table, 2, "0", &cl, &err), MFMM_OK);
    assert_ptr_equal(cl.device, (cl_device_id)(void *)&table[0]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gpu_before_cpu),
        cmocka_unit_test(test_cpu_when_gpu_lacks_float64),
        cmocka_unit_test(test_no_usable_device_is_refused),
        cmocka_unit_test(test_named_device_wins),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
#else
static void test_skipped(void **state)
{
    (void)state;
    skip();
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_skipped)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
#endif
