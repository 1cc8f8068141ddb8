//! The launch intent's string extras (`adb shell am start ... --es scene ...`), read through JNI
//! from the NativeActivity.

use std::ffi::{CStr, CString, c_void};

use android_activity::AndroidApp;
use jni_sys::{JNIEnv, JavaVM, jobject, jvalue};

/// The intent's string extra `name`, if it has one.
pub fn string_extra(app: &AndroidApp, name: &str) -> Option<String> {
    let name = CString::new(name).ok()?;
    let vm = app.vm_as_ptr() as *mut JavaVM;
    let activity = app.activity_as_ptr() as jobject;
    let mut env: *mut c_void = std::ptr::null_mut();
    // SAFETY: `vm` is the process's JavaVM; attaching this (the app's) thread is allowed and
    // idempotent; `env` receives the thread's JNIEnv.
    let attached =
        unsafe { ((**vm).v1_1.AttachCurrentThread)(vm, &mut env, std::ptr::null_mut()) } == 0;
    if !attached || env.is_null() {
        return None;
    }
    let env = env as *mut JNIEnv;
    // SAFETY: `env` is this thread's JNIEnv and `activity` the live activity's global reference;
    // every call below is a JNI 1.1 function with the signature the class has, and every local
    // reference made is deleted.
    unsafe { extra(env, activity, &name) }
}

/// `activity.getIntent().getStringExtra(name)`.
///
/// # Safety
/// `env` must be the current thread's JNIEnv and `activity` a valid reference to an
/// `android.app.Activity`.
unsafe fn extra(env: *mut JNIEnv, activity: jobject, name: &CStr) -> Option<String> {
    // SAFETY: the caller's contract; each function pointer comes from the JNI function table.
    unsafe {
        let f = &**env;
        let clear = |env| {
            if !(f.v1_1.ExceptionOccurred)(env).is_null() {
                (f.v1_1.ExceptionClear)(env);
                return true;
            }
            false
        };
        // The method `name` with signature `sig` of the object's class (the class reference is
        // dropped at once).
        let method = |object, name: &CStr, sig: &CStr| {
            let class = (f.v1_1.GetObjectClass)(env, object);
            let id = (f.v1_1.GetMethodID)(env, class, name.as_ptr(), sig.as_ptr());
            (f.v1_1.DeleteLocalRef)(env, class);
            (!clear(env) && !id.is_null()).then_some(id)
        };
        let get_intent = method(activity, c"getIntent", c"()Landroid/content/Intent;")?;
        let intent = (f.v1_1.CallObjectMethod)(env, activity, get_intent);
        if clear(env) || intent.is_null() {
            return None;
        }
        let Some(get_extra) = method(
            intent,
            c"getStringExtra",
            c"(Ljava/lang/String;)Ljava/lang/String;",
        ) else {
            (f.v1_1.DeleteLocalRef)(env, intent);
            return None;
        };
        let key = (f.v1_1.NewStringUTF)(env, name.as_ptr());
        let args = [jvalue { l: key }];
        let value = (f.v1_1.CallObjectMethodA)(env, intent, get_extra, args.as_ptr());
        (f.v1_1.DeleteLocalRef)(env, key);
        (f.v1_1.DeleteLocalRef)(env, intent);
        if clear(env) || value.is_null() {
            return None;
        }
        let chars = (f.v1_1.GetStringUTFChars)(env, value, std::ptr::null_mut());
        let text = (!chars.is_null()).then(|| CStr::from_ptr(chars).to_string_lossy().into_owned());
        if !chars.is_null() {
            (f.v1_1.ReleaseStringUTFChars)(env, value, chars);
        }
        (f.v1_1.DeleteLocalRef)(env, value);
        text
    }
}
